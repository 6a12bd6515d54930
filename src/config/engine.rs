//! The `[engine]` section of the settings: the mechanism around the rod and the cylinder
//! pressure trace, with their checks.

use super::{MAX_LENGTH_MM, MAX_MASS_KG, check_upper_bounds};
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Deserializer, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The path of a pressure trace. It is interned (each distinct path is stored once for the
/// life of the process) so that the settings stay `Copy`; written and read as a string.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct TracePath(&'static str);

impl TracePath {
    pub fn new(path: &str) -> TracePath {
        use std::collections::HashSet;
        use std::sync::{Mutex, OnceLock};
        static PATHS: OnceLock<Mutex<HashSet<&'static str>>> = OnceLock::new();
        let mut set = PATHS
            .get_or_init(Default::default)
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        let interned = match set.get(path) {
            Some(p) => *p,
            None => {
                let p: &'static str = Box::leak(path.to_owned().into_boxed_str());
                set.insert(p);
                p
            }
        };
        TracePath(interned)
    }

    pub fn as_path(&self) -> &'static Path {
        Path::new(self.0)
    }
}

impl<'de> Deserialize<'de> for TracePath {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        Ok(TracePath::new(&String::deserialize(d)?))
    }
}

/// The engine around the rod (SPEC "The engine"): crank, piston and the cylinder
/// pressure. Defaults: the thesis' test rig (SPEC "The mechanism") without gas force, so that
/// every default result stays as it is; the default is not written into `results.json`.
///
/// With `pressure_trace`, stage 2 runs over the four-stroke cycle (720°) with the gas force
/// F_gas(φ) = p(φ) · π D²/4 on the piston ([`crate::mechanism::GasForce`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EngineConfig {
    /// Crank radius r [mm] (stroke 2r).
    pub crank_radius_mm: f64,
    /// Piston assembly m₄: piston, pin and rings [kg].
    pub piston_mass_kg: f64,
    /// Crank mass m₂ [kg].
    pub crank_mass_kg: f64,
    /// Crank inertia I₂ about the main bearing O [kg·m²].
    pub crank_inertia_kgm2: f64,
    /// Crank eccentricity e: the crank centroid on OA at e from O, towards A for e > 0 [mm].
    pub crank_eccentricity_mm: f64,
    /// Cylinder bore D [mm]: piston area π D²/4 (used only with a pressure trace).
    pub cylinder_bore_mm: f64,
    /// Cylinder pressure trace (CSV: `crank_angle_deg` 0–720, 0 = firing top dead centre,
    /// `pressure_bar` gauge; [`crate::mechanism::PressureTrace`]). Relative to the
    /// configuration file's folder; stored resolved. None: no gas force.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pressure_trace: Option<TracePath>,
}

impl Default for EngineConfig {
    fn default() -> Self {
        EngineConfig {
            crank_radius_mm: 46.0,
            piston_mass_kg: 5.2269229374,
            crank_mass_kg: 8.9459574505,
            crank_inertia_kgm2: 0.016438481547370,
            crank_eccentricity_mm: 5.190636979,
            cylinder_bore_mm: 82.0,
            pressure_trace: None,
        }
    }
}

impl EngineConfig {
    /// True for the thesis' test rig without gas force (then `[engine]` is not serialized).
    pub fn is_default(&self) -> bool {
        *self == EngineConfig::default()
    }

    /// The mechanism for a rod of centre distance `centre_distance_m`. Values equal to the
    /// defaults give exactly [`MechanismParams::default`]'s numbers (no mm → m rounding), so the
    /// default study is unchanged to the bit.
    pub fn mechanism(
        &self,
        centre_distance_m: f64,
        gravity: bool,
    ) -> crate::mechanism::MechanismParams {
        let d = EngineConfig::default();
        let mut p = crate::mechanism::MechanismParams {
            centre_distance_m,
            ..Default::default()
        }
        .with_gravity(gravity);
        let changed = |v: f64, default: f64| (v != default).then_some(v);
        if let Some(v) = changed(self.crank_radius_mm, d.crank_radius_mm) {
            p.crank_radius_m = v * 1e-3;
        }
        if let Some(v) = changed(self.piston_mass_kg, d.piston_mass_kg) {
            p.piston_mass_kg = v;
        }
        if let Some(v) = changed(self.crank_mass_kg, d.crank_mass_kg) {
            p.crank_mass_kg = v;
        }
        if let Some(v) = changed(self.crank_inertia_kgm2, d.crank_inertia_kgm2) {
            p.crank_inertia_o_kgm2 = v;
        }
        if let Some(v) = changed(self.crank_eccentricity_mm, d.crank_eccentricity_mm) {
            p.crank_eccentricity_m = v * 1e-3;
        }
        p
    }

    /// Reads and checks the pressure trace; errors name the file and the line.
    pub fn pressure_trace(&self) -> Result<Option<crate::mechanism::PressureTrace>> {
        let Some(path) = self.pressure_trace else {
            return Ok(None);
        };
        let path = path.as_path();
        // as the settings: bytes that are not UTF-8 read as U+FFFD (a row holding one is refused
        // with its line)
        let bytes = std::fs::read(path)
            .with_context(|| format!("{}: cannot read the pressure trace", path.display()))?;
        let trace = crate::mechanism::PressureTrace::parse(&String::from_utf8_lossy(&bytes))
            .map_err(|e| anyhow::anyhow!("{}: invalid pressure trace: {e}", path.display()))?;
        Ok(Some(trace))
    }

    /// The gas force on the piston, F_gas(φ) = p(φ) π D²/4, if a trace is configured.
    pub fn gas_force(&self) -> Result<Option<Arc<crate::mechanism::GasForce>>> {
        Ok(self.pressure_trace()?.map(|t| {
            Arc::new(crate::mechanism::GasForce::from_trace(
                &t,
                self.cylinder_bore_mm * 1e-3,
            ))
        }))
    }

    pub(super) fn check(&self) -> Result<()> {
        let positive = [
            ("engine.crank_radius_mm", self.crank_radius_mm),
            ("engine.piston_mass_kg", self.piston_mass_kg),
            ("engine.crank_mass_kg", self.crank_mass_kg),
            ("engine.crank_inertia_kgm2", self.crank_inertia_kgm2),
            ("engine.cylinder_bore_mm", self.cylinder_bore_mm),
        ];
        for (key, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                bail!("`{key}` must be a positive number, got {v}");
            }
        }
        check_upper_bounds(&[
            (
                "engine.crank_radius_mm",
                self.crank_radius_mm,
                MAX_LENGTH_MM,
                "mm",
            ),
            (
                "engine.cylinder_bore_mm",
                self.cylinder_bore_mm,
                MAX_LENGTH_MM,
                "mm",
            ),
            (
                "engine.piston_mass_kg",
                self.piston_mass_kg,
                MAX_MASS_KG,
                "kg",
            ),
            (
                "engine.crank_mass_kg",
                self.crank_mass_kg,
                MAX_MASS_KG,
                "kg",
            ),
            (
                "engine.crank_inertia_kgm2",
                self.crank_inertia_kgm2,
                MAX_MASS_KG,
                "kg·m²",
            ),
            (
                "engine.crank_eccentricity_mm",
                self.crank_eccentricity_mm.abs(),
                MAX_LENGTH_MM,
                "mm (in magnitude)",
            ),
        ])?;
        let e = self.crank_eccentricity_mm * 1e-3;
        if !e.is_finite() {
            bail!("`engine.crank_eccentricity_mm` must be a finite number");
        }
        if self.crank_inertia_kgm2 <= self.crank_mass_kg * e * e {
            bail!(
                "`engine.crank_inertia_kgm2` = {} must exceed crank_mass e² = {} kg·m² (the \
                 centroidal inertia I₂ − m₂ e², thesis eq. 3.43, must be positive)",
                self.crank_inertia_kgm2,
                self.crank_mass_kg * e * e
            );
        }
        self.pressure_trace()?;
        Ok(())
    }

    /// Resolves a relative trace path against the folder of the configuration file.
    pub(super) fn resolve(&mut self, config_file: &Path) {
        if let Some(p) = self.pressure_trace
            && p.as_path().is_relative()
        {
            let folder = config_file.parent().unwrap_or(Path::new(""));
            let joined: PathBuf = folder.join(p.as_path());
            self.pressure_trace = Some(TracePath::new(&joined.to_string_lossy()));
        }
    }
}
