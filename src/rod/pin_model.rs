//! How stiff the pins are in the contact load model (`[fem] pins`): rigid (the default), or
//! elastic ([`crate::fem::contact::elastic_pin`]) of the rod's material, held at a rigid core or
//! at the bore's two faces.

use serde::{Deserialize, Serialize};

use crate::fem::contact::{PinElasticity, PinHold};
use crate::fem::error::{FemError, Result};
use crate::fem::material::Material;

/// The pins' stiffness under contact.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PinModel {
    /// Rigid cylinders (the default).
    #[default]
    Rigid,
    /// Elastic pins held at a rigid core: the pin's own compliance under the pressure, no bending.
    Elastic,
    /// Elastic pins held at the bore's two faces (the bosses or webs right beside the eye): the
    /// pin also bends and shears between them.
    ElasticEnds,
}

/// The inner radius over the bore's radius where none is given: a solid pin around a core of a
/// fifth of its radius.
pub const DEFAULT_PIN_INNER_RATIO: f64 = 0.2;

impl PinModel {
    /// Whether this is the default (rigid), e.g. to leave it out of written results.
    pub fn is_rigid(&self) -> bool {
        *self == PinModel::Rigid
    }

    /// The kernel's elasticity of these pins, of `material`, with inner radius `inner_ratio` ×
    /// the bore's radius (`None`: [`DEFAULT_PIN_INNER_RATIO`]); `None` for rigid pins.
    pub fn elasticity(
        &self,
        material: &Material,
        inner_ratio: Option<f64>,
    ) -> Result<Option<PinElasticity>> {
        let hold = match self {
            PinModel::Rigid => return Ok(None),
            PinModel::Elastic => PinHold::Core,
            PinModel::ElasticEnds => PinHold::Ends,
        };
        let inner_ratio = inner_ratio.unwrap_or(DEFAULT_PIN_INNER_RATIO);
        if !(inner_ratio > 0.0 && inner_ratio < 1.0) {
            return Err(FemError::InvalidInput(format!(
                "the pins' inner radius ratio must lie in (0, 1), got {inner_ratio}"
            )));
        }
        Ok(Some(PinElasticity {
            material: *material,
            hold,
            inner_ratio,
        }))
    }
}
