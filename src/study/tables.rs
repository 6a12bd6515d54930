//! Tables for people (Markdown), shared by the commands and the study's reports.

use crate::geometry::design::DesignMass;

/// The table for people: the figures a rod designer compares with CAD, in mm and kg·m².
pub fn mass_table(designs: &[&DesignMass]) -> String {
    let mut out = String::from(
        "| design | mass [kg] | volume [cm³] | l1 [mm] | offset [mm] | I_zz pin axis [kg·m²] | I_xx long axis [kg·m²] | bores A / B [mm] | triangles |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for d in designs {
        out.push_str(&format!(
            "| {} | {:.6} | {:.3} | {:.3} | {:.3} | {:.6e} | {:.6e} | Ø{:.1} / Ø{:.1} | {} |\n",
            d.design,
            d.mass_kg,
            d.volume_m3 * 1e6,
            d.l1_m * 1e3,
            d.offset_m * 1e3,
            d.i_zz_kgm2,
            d.i_xx_kgm2,
            2e3 * d.crank_bore_radius_m,
            2e3 * d.piston_bore_radius_m,
            d.triangles
        ));
    }
    out
}
