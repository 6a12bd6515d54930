//! The methods of the `free` scene, by name.

use crate::integrators::OdeMethod;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// A method for the free-running crank. Names (for `FromStr`/`Display`/serde):
/// `initial-acceleration`, `rk45`, `rk23`, `bdf`, `rosenbrock`, `trbdf2`, `dae-index1`,
/// `dae-genalpha`.
///
/// The first six ([`Method::REDUCED`]) integrate the reduced equation of motion (eq. 3.24 /
/// 4.1) and map to an [`OdeMethod`]; the last two ([`Method::DAE`]) integrate the multibody
/// model of thesis §3.2 as a DAE (see [`super::dae`]) and return `None` from
/// [`Method::ode_method`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// The thesis' initial-acceleration method (§4.1.1), fixed step.
    InitialAcceleration,
    /// Dormand–Prince 5(4) (ode45).
    Rk45,
    /// Bogacki–Shampine 3(2) (ode23).
    Rk23,
    /// Variable-order BDF 1–5 (ode15s-style; ADAMS GSTIFF is a BDF).
    Bdf,
    /// Modified Rosenbrock 2(3) (ode23s).
    Rosenbrock,
    /// TR-BDF2 (ode23tb).
    #[serde(rename = "trbdf2")]
    TrBdf2,
    /// Multibody DAE, stabilised index-1 form (projection by default) with RK45.
    DaeIndex1,
    /// Multibody DAE, index-3 form with generalized-α (Arnold & Brüls 2007), fixed step.
    #[serde(rename = "dae-genalpha")]
    DaeGenAlpha,
}

impl Method {
    /// Every method, in table order.
    pub const ALL: [Method; 8] = [
        Method::InitialAcceleration,
        Method::Rk45,
        Method::Rk23,
        Method::Bdf,
        Method::Rosenbrock,
        Method::TrBdf2,
        Method::DaeIndex1,
        Method::DaeGenAlpha,
    ];

    /// The methods on the reduced model (eq. 3.24 / 4.1).
    pub const REDUCED: [Method; 6] = [
        Method::InitialAcceleration,
        Method::Rk45,
        Method::Rk23,
        Method::Bdf,
        Method::Rosenbrock,
        Method::TrBdf2,
    ];

    /// The methods on the multibody DAE (thesis §3.2).
    pub const DAE: [Method; 2] = [Method::DaeIndex1, Method::DaeGenAlpha];

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Self::InitialAcceleration => "initial-acceleration",
            Self::Rk45 => "rk45",
            Self::Rk23 => "rk23",
            Self::Bdf => "bdf",
            Self::Rosenbrock => "rosenbrock",
            Self::TrBdf2 => "trbdf2",
            Self::DaeIndex1 => "dae-index1",
            Self::DaeGenAlpha => "dae-genalpha",
        }
    }

    /// `true` for the multibody DAE forms.
    pub fn is_dae(self) -> bool {
        matches!(self, Self::DaeIndex1 | Self::DaeGenAlpha)
    }

    /// The generic ODE method integrating the reduced model, if this is one.
    pub fn ode_method(self) -> Option<OdeMethod> {
        Some(match self {
            Self::InitialAcceleration => OdeMethod::InitialAcceleration,
            Self::Rk45 => OdeMethod::Rk45,
            Self::Rk23 => OdeMethod::Rk23,
            Self::Bdf => OdeMethod::Bdf,
            Self::Rosenbrock => OdeMethod::Rosenbrock,
            Self::TrBdf2 => OdeMethod::TrBdf2,
            Self::DaeIndex1 | Self::DaeGenAlpha => return None,
        })
    }

    /// `true` for the fixed-step methods (swept over step sizes, not tolerances):
    /// initial-acceleration and dae-genalpha.
    pub fn is_fixed_step(self) -> bool {
        self == Self::DaeGenAlpha || self.ode_method().is_some_and(OdeMethod::is_fixed_step)
    }

    /// `true` for the implicit methods (Newton iterations on a Jacobian).
    pub fn is_implicit(self) -> bool {
        self == Self::DaeGenAlpha || self.ode_method().is_some_and(OdeMethod::is_implicit)
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Unknown method name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown method `{0}` (expected one of: initial-acceleration, rk45, rk23, bdf, rosenbrock, \
     trbdf2, dae-index1, dae-genalpha)"
)]
pub struct UnknownMethod(pub String);

impl FromStr for Method {
    type Err = UnknownMethod;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s.trim())
            .ok_or_else(|| UnknownMethod(s.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>().unwrap(), m);
            assert_eq!(
                serde_json::to_string(&m).unwrap(),
                format!("\"{}\"", m.name())
            );
            assert_eq!(
                serde_json::from_str::<Method>(&format!("\"{m}\"")).unwrap(),
                m
            );
        }
        assert_eq!("dae-index1".parse::<Method>().unwrap(), Method::DaeIndex1);
        assert_eq!(
            serde_json::to_string(&Method::DaeGenAlpha).unwrap(),
            "\"dae-genalpha\""
        );
        assert!(
            Method::DAE
                .iter()
                .all(|m| m.is_dae() && m.ode_method().is_none())
        );
        assert!(Method::REDUCED.iter().all(|m| !m.is_dae()));
        let e = "ode45".parse::<Method>().unwrap_err();
        assert!(e.to_string().contains("unknown method `ode45`"));
    }
}
