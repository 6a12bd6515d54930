//! The gas force on the piston over the four-stroke cycle (SPEC "The engine").
//!
//! A cylinder pressure trace p(φ) — gauge pressure over the crank angle φ ∈ [0°, 720°], 0 = firing
//! top dead centre — acts on the piston crown of area A = π D²/4 (D the cylinder bore). The force
//! on the piston is
//!
//! F_gas(φ) = p(φ) · A, directed along the cylinder axis **towards the crank** (global −x),
//!
//! so a positive gauge pressure compresses the rod. Gauge pressure, because the underside of the
//! piston sees the crankcase at ambient pressure. Between the trace's rows p is interpolated
//! linearly, and the trace is periodic with period 720° (4π): F_gas(φ + 4π) = F_gas(φ). Both
//! solution methods evaluate [`GasForce::at`] at the crank angle of each instant: the closed form
//! at the prescribed φ, the multibody core at the crank's body coordinate φ₂ (an applied load of
//! the system, [`AppliedLoad::GasForce`](super::system::AppliedLoad::GasForce), entering h of
//! thesis eq. 3.31).
//!
//! # The trace file
//! CSV with a header naming the two columns `crank_angle_deg` and `pressure_bar` (either order);
//! lines starting with `#` are comments (where a trace states its source), blank lines are
//! skipped. The angles must start at exactly 0, end at exactly 720 and increase strictly; the
//! pressure at 720° must equal the one at 0° (the trace is periodic); no absolute pressure
//! p + 1.01325 bar may be negative (standard atmosphere, ISO 2533), and no gauge pressure exceed
//! [`MAX_PRESSURE_BAR`]. A leading UTF-8 byte-order mark is skipped. Every refusal names the line.

use serde::Serialize;

/// The standard atmosphere (bar): absolute = gauge + this (ISO 2533, 101 325 Pa).
pub const ATMOSPHERE_BAR: f64 = 1.01325;

/// Length of the four-stroke cycle (degrees of crank angle).
pub const CYCLE_DEG: f64 = 720.0;

/// Largest gauge pressure of a trace row, bar: peak firing pressures of diesel engines reach
/// about 250–300 bar; a row beyond 5000 bar is a unit slip (Pa, kPa) or a typo.
pub const MAX_PRESSURE_BAR: f64 = 5000.0;

/// A cylinder pressure trace as read from its CSV (degrees, bar gauge).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PressureTrace {
    /// Crank angle (°), strictly increasing from 0 to 720.
    pub crank_angle_deg: Vec<f64>,
    /// Gauge pressure (bar) at each angle.
    pub pressure_bar: Vec<f64>,
}

impl PressureTrace {
    /// Parses and checks a trace (see the module documentation). The error names the line
    /// (1-based, counting the header and comments) and what is wrong with it.
    pub fn parse(text: &str) -> std::result::Result<PressureTrace, String> {
        // a spreadsheet's UTF-8 export may begin with a byte-order mark
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let (header_line, header) = lines
            .next()
            .ok_or("empty trace: expected a header `crank_angle_deg,pressure_bar` and rows")?;
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        let column = |name: &str| names.iter().position(|n| *n == name);
        let (ia, ip) = match (column("crank_angle_deg"), column("pressure_bar")) {
            (Some(a), Some(p)) if names.len() == 2 => (a, p),
            _ => {
                return Err(format!(
                    "line {header_line}: the header must name the two columns `crank_angle_deg` \
                     and `pressure_bar`, got `{header}`"
                ));
            }
        };
        let mut trace = PressureTrace {
            crank_angle_deg: Vec::new(),
            pressure_bar: Vec::new(),
        };
        let mut first_line = 0;
        let mut last_line = 0;
        for (line, row) in lines {
            let cells: Vec<&str> = row.split(',').map(str::trim).collect();
            if cells.len() != 2 {
                return Err(format!(
                    "line {line}: expected 2 values (crank_angle_deg, pressure_bar), got {} in `{row}`",
                    cells.len()
                ));
            }
            let number = |s: &str, what: &str| {
                s.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| format!("line {line}: {what} `{s}` is not a finite number"))
            };
            let angle = number(cells[ia], "crank_angle_deg")?;
            let p = number(cells[ip], "pressure_bar")?;
            if let Some(&prev) = trace.crank_angle_deg.last()
                && angle <= prev
            {
                return Err(format!(
                    "line {line}: the crank angle must increase strictly (monotone), but \
                     {angle}° follows {prev}°"
                ));
            }
            if p > MAX_PRESSURE_BAR {
                return Err(format!(
                    "line {line}: gauge pressure {p:e} bar at {angle}° is beyond any engine's \
                     (at most {MAX_PRESSURE_BAR} bar): the column is in bar (a trace in Pa or \
                     kPa must be converted)"
                ));
            }
            if p + ATMOSPHERE_BAR < 0.0 {
                return Err(format!(
                    "line {line}: gauge pressure {p} bar at {angle}° is a negative absolute \
                     pressure ({:.5} bar; absolute = gauge + {ATMOSPHERE_BAR} bar)",
                    p + ATMOSPHERE_BAR
                ));
            }
            if trace.crank_angle_deg.is_empty() {
                first_line = line;
            }
            last_line = line;
            trace.crank_angle_deg.push(angle);
            trace.pressure_bar.push(p);
        }
        let n = trace.crank_angle_deg.len();
        if n < 2 {
            return Err(format!(
                "the trace has {n} row(s): it must cover the cycle from 0 to {CYCLE_DEG}° crank angle"
            ));
        }
        if trace.crank_angle_deg[0] != 0.0 {
            return Err(format!(
                "line {first_line}: the trace must cover the cycle 0–{CYCLE_DEG}°, but it starts \
                 at {}°",
                trace.crank_angle_deg[0]
            ));
        }
        if trace.crank_angle_deg[n - 1] != CYCLE_DEG {
            return Err(format!(
                "line {last_line}: the trace must cover the cycle 0–{CYCLE_DEG}°, but it ends at \
                 {}°",
                trace.crank_angle_deg[n - 1]
            ));
        }
        let (p0, p1) = (trace.pressure_bar[0], trace.pressure_bar[n - 1]);
        let scale = trace
            .pressure_bar
            .iter()
            .fold(ATMOSPHERE_BAR, |m, p| m.max(p.abs()));
        if (p1 - p0).abs() > 1e-9 * scale {
            return Err(format!(
                "line {last_line}: the trace is periodic, so the pressure at {CYCLE_DEG}° must \
                 equal the one at 0° ({p0} bar), got {p1} bar"
            ));
        }
        Ok(trace)
    }

    /// Largest gauge pressure (bar) and its crank angle (°).
    pub fn peak(&self) -> (f64, f64) {
        let mut k = 0;
        for (i, p) in self.pressure_bar.iter().enumerate() {
            if *p > self.pressure_bar[k] {
                k = i;
            }
        }
        (self.pressure_bar[k], self.crank_angle_deg[k])
    }
}

/// Piston crown area A = π D²/4 (m²) for the bore D (m).
pub fn piston_area_m2(bore_m: f64) -> f64 {
    0.25 * std::f64::consts::PI * bore_m * bore_m
}

/// The gas force on the piston as a periodic, piecewise-linear function of the crank angle:
/// F_gas(φ) = p(φ) · A (N, positive = pushing the piston towards the crank), period 720°.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GasForce {
    /// Node angles (°), strictly increasing from 0 to 720.
    angle_deg: Vec<f64>,
    /// Force at each node (N).
    force_n: Vec<f64>,
}

impl GasForce {
    /// The trace's pressure (bar = 10⁵ Pa) times the piston area π D²/4 of the bore D (m).
    pub fn from_trace(trace: &PressureTrace, bore_m: f64) -> GasForce {
        let area = piston_area_m2(bore_m);
        GasForce {
            angle_deg: trace.crank_angle_deg.clone(),
            force_n: trace.pressure_bar.iter().map(|p| p * 1e5 * area).collect(),
        }
    }

    /// The same force at every crank angle (N), e.g. for quasi-static checks.
    pub fn constant(force_n: f64) -> GasForce {
        GasForce {
            angle_deg: vec![0.0, CYCLE_DEG],
            force_n: vec![force_n, force_n],
        }
    }

    /// F_gas at crank angle φ (rad, any value: reduced modulo 4π), linear between the nodes.
    pub fn at(&self, phi_rad: f64) -> f64 {
        let x = phi_rad.to_degrees().rem_euclid(CYCLE_DEG);
        let a = &self.angle_deg;
        // the first node above x (a[0] = 0 ≤ x < 720 = a[n-1], so 1 ≤ j ≤ n-1)
        let j = a.partition_point(|v| *v <= x).clamp(1, a.len() - 1);
        let (x0, x1) = (a[j - 1], a[j]);
        let (f0, f1) = (self.force_n[j - 1], self.force_n[j]);
        f0 + (f1 - f0) * ((x - x0) / (x1 - x0))
    }

    /// Largest force over the cycle (N), at a node of the trace.
    pub fn max_n(&self) -> f64 {
        self.force_n
            .iter()
            .fold(f64::NEG_INFINITY, |m, v| m.max(*v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "# comment\ncrank_angle_deg,pressure_bar\n0,1\n360,0.5\n720,1\n";

    #[test]
    fn parses_interpolates_and_wraps() {
        let t = PressureTrace::parse(GOOD).unwrap();
        assert_eq!(t.crank_angle_deg, vec![0.0, 360.0, 720.0]);
        let f = GasForce::from_trace(&t, 0.1);
        let a = piston_area_m2(0.1);
        assert!((f.at(0.0) - 1e5 * a).abs() < 1e-9);
        // 180° is half-way from 1 bar to 0.5 bar
        assert!((f.at(std::f64::consts::PI) - 0.75e5 * a).abs() < 1e-8);
        // periodic: −180° is 540°
        assert!((f.at(-std::f64::consts::PI) - 0.75e5 * a).abs() < 1e-8);
        assert!((f.at(4.0 * std::f64::consts::PI + 1e-3) - f.at(1e-3)).abs() < 1e-8);
        // columns in either order
        let swapped = PressureTrace::parse("pressure_bar,crank_angle_deg\n1,0\n1,720\n").unwrap();
        assert_eq!(swapped.pressure_bar, vec![1.0, 1.0]);
    }

    #[test]
    fn refusals_name_the_line() {
        let cases = [
            ("angle,p\n0,1\n720,1\n", "line 1", "header"),
            (
                "crank_angle_deg,pressure_bar\n0,1\n0,2\n720,1\n",
                "line 3",
                "monotone",
            ),
            (
                "crank_angle_deg,pressure_bar\n0,1\n360,-1.5\n720,1\n",
                "line 3",
                "negative absolute",
            ),
            (
                "crank_angle_deg,pressure_bar\n10,1\n720,1\n",
                "line 2",
                "cover",
            ),
            (
                "crank_angle_deg,pressure_bar\n0,1\n700,1\n",
                "line 3",
                "cover",
            ),
            (
                "crank_angle_deg,pressure_bar\n0,1\n720,2\n",
                "line 3",
                "periodic",
            ),
            (
                "crank_angle_deg,pressure_bar\n0,1\n360,x\n720,1\n",
                "line 3",
                "finite",
            ),
            (
                "crank_angle_deg,pressure_bar\n0,1,2\n720,1\n",
                "line 2",
                "2 values",
            ),
        ];
        for (text, line, what) in cases {
            let e = PressureTrace::parse(text).unwrap_err();
            assert!(e.contains(line) && e.contains(what), "{text:?}: {e}");
        }
        // −1 bar gauge is a vacuum of 0.01325 bar absolute: allowed
        assert!(PressureTrace::parse("crank_angle_deg,pressure_bar\n0,-1\n720,-1\n").is_ok());
    }
}
