//! The optional sidecar `NAME.toml` beside `NAME.stl` (SPEC "Sidecar").
//!
//! Keys: `name` (display name), `units` (`mm` default, `cm`, `m`, `in`; for a STEP the unit its
//! numbers are read in, overriding the unit the file declares), `density` (kg/m³,
//! default 7800), `crank_pin` and `piston_pin` (pin centres in file units), `pin_axis` (`"x"`,
//! `"y"`, `"z"` or a vector `[ax, ay, az]`). Unknown keys and wrong types are errors, so a typo
//! never silently falls back to a default.
//!
//! Pins: when the sidecar gives neither pin, both are left to the bore finder
//! ([`super::bore_finder`], called by [`super::design::load_design`]), restricted to `pin_axis`
//! if that is given. When it gives one pin, the other takes the spec's mechanism as before
//! (A at the origin, B 180 mm along x from A, in the file's units) and the axis defaults to z.

use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Length unit of an STL file's coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Units {
    #[default]
    Mm,
    Cm,
    M,
    In,
}

impl Units {
    /// Metres per file unit.
    pub fn to_metres(self) -> f64 {
        match self {
            Units::Mm => 1e-3,
            Units::Cm => 1e-2,
            Units::M => 1.0,
            Units::In => 0.0254,
        }
    }

    pub fn symbol(self) -> &'static str {
        match self {
            Units::Mm => "mm",
            Units::Cm => "cm",
            Units::M => "m",
            Units::In => "in",
        }
    }
}

/// The pin axis: a coordinate axis by name or any non-zero vector.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum PinAxis {
    Named(String),
    Vector(Vec<f64>),
}

impl Default for PinAxis {
    fn default() -> Self {
        PinAxis::Named("z".into())
    }
}

/// Density of steel used when the sidecar gives none [kg/m³] (SPEC "Stage 1").
pub const DEFAULT_DENSITY: f64 = 7800.0;
/// The spec's centre distance A→B [m], the default position of the piston pin.
pub const DEFAULT_CENTRE_DISTANCE: f64 = 0.18;

/// Contents of a sidecar file, as written (file units).
#[derive(Debug, Clone, PartialEq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Sidecar {
    pub name: Option<String>,
    /// The unit of the file's numbers; for a STEP it overrides the unit the file declares.
    pub units: Option<Units>,
    pub density: Option<f64>,
    pub crank_pin: Option<Vec<f64>>,
    pub piston_pin: Option<Vec<f64>>,
    pub pin_axis: Option<PinAxis>,
}

/// The sidecar with every default filled in and every value checked, in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignSettings {
    pub name: Option<String>,
    pub units: Units,
    /// The sidecar gives `units` (for a STEP: its numbers are read in them, whatever unit the
    /// file declares).
    pub units_given: bool,
    pub density: f64,
    /// The pin centres [m], both `Some` when the sidecar gives at least one of them (the other
    /// then the spec's default), both `None` when they are to be found from the geometry.
    pub crank_pin_m: Option<Vector3<f64>>,
    pub piston_pin_m: Option<Vector3<f64>>,
    /// The pin axis (unit) if the sidecar gives it.
    pub pin_axis: Option<Vector3<f64>>,
    /// The sidecar file read, if there was one.
    pub source: Option<PathBuf>,
}

/// Path of the sidecar that belongs to `stl` (same stem, `.toml`).
pub fn sidecar_path(stl: &Path) -> PathBuf {
    stl.with_extension("toml")
}

impl DesignSettings {
    /// Reads the sidecar beside `stl` if it exists, else the spec's defaults.
    pub fn for_stl(stl: &Path) -> Result<Self> {
        let path = sidecar_path(stl);
        if !path.exists() {
            return Sidecar::default().resolve(None);
        }
        // TOML is UTF-8: a byte-order mark is dropped, and bytes of another encoding (a Latin-1
        // comment) are read as U+FFFD, so that only the keys' values decide
        let bytes = std::fs::read(&path)
            .with_context(|| format!("{}: cannot read the sidecar", path.display()))?;
        let text = String::from_utf8_lossy(&bytes);
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let sidecar: Sidecar =
            toml::from_str(text).with_context(|| format!("{}: invalid sidecar", path.display()))?;
        sidecar
            .resolve(Some(path.clone()))
            .with_context(|| format!("{}: invalid sidecar", path.display()))
    }
}

impl Sidecar {
    /// Fills in defaults, checks the values and converts the pins to metres.
    pub fn resolve(self, source: Option<PathBuf>) -> Result<DesignSettings> {
        let units = self.units.unwrap_or_default();
        let scale = units.to_metres();
        let density = self.density.unwrap_or(DEFAULT_DENSITY);
        if !(density.is_finite() && density > 0.0) {
            bail!("`density` must be a positive number of kg/m³, got {density}");
        }
        let given = self.crank_pin.is_some() || self.piston_pin.is_some();
        let crank = match &self.crank_pin {
            Some(p) => Vector3::from(three("crank_pin", p)?),
            None => Vector3::zeros(),
        };
        let piston = match &self.piston_pin {
            Some(p) => Vector3::from(three("piston_pin", p)?),
            None => crank + Vector3::x() * (DEFAULT_CENTRE_DISTANCE / scale),
        };
        for (key, p) in [("crank_pin", crank), ("piston_pin", piston)] {
            if !p.iter().all(|c| c.is_finite()) {
                bail!("`{key}` must have finite coordinates, got {p:?}");
            }
        }
        let axis = match &self.pin_axis {
            None => None,
            Some(PinAxis::Named(n)) => Some(match n.as_str() {
                "x" => Vector3::x(),
                "y" => Vector3::y(),
                "z" => Vector3::z(),
                other => {
                    bail!("`pin_axis` must be \"x\", \"y\", \"z\" or [ax, ay, az], got {other:?}")
                }
            }),
            Some(PinAxis::Vector(v)) => {
                let v = Vector3::from(three("pin_axis", v)?);
                if !(v.iter().all(|c| c.is_finite()) && v.norm() > 0.0) {
                    bail!("`pin_axis` must be a non-zero finite vector, got {v:?}");
                }
                Some(v.normalize())
            }
        };
        Ok(DesignSettings {
            name: self.name,
            units,
            units_given: self.units.is_some(),
            density,
            crank_pin_m: given.then(|| crank * scale),
            piston_pin_m: given.then(|| piston * scale),
            pin_axis: axis,
            source,
        })
    }
}

/// A point or vector of the sidecar: exactly three numbers.
fn three(key: &str, v: &[f64]) -> Result<[f64; 3]> {
    match v {
        &[x, y, z] => Ok([x, y, z]),
        _ => bail!(
            "`{key}` must have 3 coordinates [x, y, z], got {} ({v:?})",
            v.len()
        ),
    }
}

impl DesignSettings {
    /// The spec's mechanism in the file's units, used when the sidecar gives no pins and the
    /// geometry has no cylindrical bore to find them from: A at the origin, B 180 mm along x,
    /// the sidecar's axis or z (the same numbers as a sidecar giving one pin at the origin).
    pub fn default_pins(&self) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let scale = self.units.to_metres();
        let crank = Vector3::zeros();
        let piston = crank + Vector3::x() * (DEFAULT_CENTRE_DISTANCE / scale);
        (
            crank * scale,
            piston * scale,
            self.pin_axis.unwrap_or_else(Vector3::z),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_spec_mechanism() {
        let s = Sidecar::default().resolve(None).unwrap();
        assert_eq!(s.density, 7800.0);
        assert_eq!(
            (s.crank_pin_m, s.piston_pin_m, s.pin_axis),
            (None, None, None)
        );
        let (a, b, axis) = s.default_pins();
        assert_eq!(a, Vector3::zeros());
        assert!((b - Vector3::new(0.18, 0.0, 0.0)).norm() < 1e-15);
        assert_eq!(axis, Vector3::z());
        // one pin given: the other from the spec's mechanism, axis z later
        let one: Sidecar = toml::from_str("crank_pin = [0.0, 0.0, 0.0]").unwrap();
        let one = one.resolve(None).unwrap();
        assert_eq!(one.piston_pin_m, Some(b));
        assert_eq!(one.pin_axis, None);
    }

    #[test]
    fn metres_keep_the_default_centre_distance() {
        let s: Sidecar = toml::from_str("units = \"m\"").unwrap();
        let s = s.resolve(None).unwrap();
        assert!((s.default_pins().1.x - 0.18).abs() < 1e-15);
    }

    #[test]
    fn unknown_keys_and_wrong_types_are_refused() {
        let err = toml::from_str::<Sidecar>("densty = 7000.0").unwrap_err();
        assert!(err.to_string().contains("unknown field `densty`"), "{err}");
        assert!(toml::from_str::<Sidecar>("density = \"heavy\"").is_err());
        assert!(toml::from_str::<Sidecar>("units = \"furlong\"").is_err());
        let bad: Sidecar = toml::from_str("density = -1.0").unwrap();
        assert!(bad.resolve(None).is_err());
        let bad: Sidecar = toml::from_str("pin_axis = \"w\"").unwrap();
        assert!(bad.resolve(None).is_err());
        // a fourth coordinate, or a missing third, is named, never dropped or padded
        for (text, key) in [
            (
                "crank_pin = [0, 0, 0, 99]",
                "`crank_pin` must have 3 coordinates",
            ),
            (
                "piston_pin = [180.0, 0.0]",
                "`piston_pin` must have 3 coordinates",
            ),
            (
                "pin_axis = [0, 0, 1, 0]",
                "`pin_axis` must have 3 coordinates",
            ),
        ] {
            let bad: Sidecar = toml::from_str(text).unwrap();
            let e = bad.resolve(None).unwrap_err().to_string();
            assert!(e.contains(key), "{text}: {e}");
        }
    }
}
