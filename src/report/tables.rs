//! Tables for people (Markdown), shared by the commands and the study's reports.

use crate::geometry::design::DesignMass;

/// The table for people: the figures a rod designer compares with CAD, in mm and kg·m².
pub fn mass_table(designs: &[&DesignMass]) -> String {
    let mut out = String::from(
        "| design | mass [kg] | volume [cm³] | l1 [mm] | offset [mm] | I_zz pin axis [kg·m²] | I_xx long axis [kg·m²] | bores A / B [mm] | triangles |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    // the mechanism-frame figures of a solid without bores are NaN: shown as "—"
    let num = |v: f64, f: &dyn Fn(f64) -> String| if v.is_finite() { f(v) } else { "—".into() };
    for d in designs {
        out.push_str(&format!(
            "| {} | {:.6} | {:.3} | {} | {} | {} | {} | {} | {} |\n",
            d.design,
            d.mass_kg,
            d.volume_m3 * 1e6,
            num(d.l1_m, &|v| format!("{:.3}", v * 1e3)),
            num(d.offset_m, &|v| format!("{:.3}", v * 1e3)),
            num(d.i_zz_kgm2, &|v| format!("{v:.6e}")),
            num(d.i_xx_kgm2, &|v| format!("{v:.6e}")),
            num(
                d.crank_bore_radius_m + d.piston_bore_radius_m,
                &|_| format!(
                    "Ø{:.1} / Ø{:.1}",
                    2e3 * d.crank_bore_radius_m,
                    2e3 * d.piston_bore_radius_m
                )
            ),
            d.triangles
        ));
    }
    out
}

/// The stage-2 table for people: the peak crank–rod pin force of each design.
pub fn dynamics_table(designs: &[&crate::stages::records::DesignDynamics]) -> String {
    let mut out = String::from(
        "| design | peak pin force [N] | at crank angle [°] | at t [s] | TDC formula [N] | ∂F/∂m3 [N/kg] | ∂F/∂l1 [N/mm] | ∂F/∂I_zz [N/(kg·m²)] | gravity |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for d in designs {
        let s = &d.sensitivity;
        out.push_str(&format!(
            "| {} | {:.2} | {:.3} | {:.5} | {:.2} | {:.2} | {:.3} | {:.2e} | {} |\n",
            d.design,
            d.peak_pin_force_n,
            d.peak_crank_angle_deg,
            d.peak_time_s,
            d.tdc_formula_n,
            s.d_mass_n_per_kg,
            s.d_l1_n_per_m * 1e-3,
            s.d_izz_n_per_kgm2,
            if d.gravity { "on" } else { "off" }
        ));
    }
    out
}
