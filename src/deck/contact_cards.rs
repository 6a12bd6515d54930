//! Contact cards of a deck (the CalculiX manual, ccx 2.20, "*SURFACE INTERACTION", "*SURFACE
//! BEHAVIOR", "*CONTACT PAIR"): frictionless, small-sliding surface-to-surface contact between
//! element-face surfaces of C3D10 elements, solved by [`super::contact`].
//!
//! * `*SURFACE INTERACTION, NAME=`, followed by
//! * `*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD` (optional line `K[, σ∞[, c0]]`: ccx's penalty
//!   slope; rodstudy solves hard contact exactly and says so in a warning) or `=LINEAR` (line
//!   `K[, σ∞[, c0]]`, K > 0: p = K · overclosure; σ∞ and c0 read and unused, with a warning);
//! * `*CONTACT PAIR, INTERACTION=, TYPE=SURFACE TO SURFACE[, SMALL SLIDING]`: lines
//!   `slave surface, master surface`.
//!
//! Refused: `*FRICTION`, TYPE=NODE TO SURFACE and MORTAR, `ADJUST=`, other pressure–overclosure
//! laws (EXPONENTIAL, TABULAR, TIED), node surfaces in a pair.

use std::path::Path;

use super::model::*;
use super::parse::{Card, error, num, required};
use crate::fem::error::Result;

impl Model {
    pub(super) fn read_surface_interaction(
        &mut self,
        path: &Path,
        card: &Card,
        current: &mut Option<String>,
    ) -> Result<()> {
        let name = required(path, card, "NAME")?.to_ascii_uppercase();
        if self.interactions.contains_key(&name) {
            return Err(error(
                path,
                card.line,
                format!("surface interaction {name} defined twice"),
            ));
        }
        self.interactions.insert(name.clone(), (None, card.line));
        *current = Some(name);
        Ok(())
    }

    pub(super) fn read_surface_behavior(
        &mut self,
        path: &Path,
        card: &Card,
        current: &Option<String>,
    ) -> Result<()> {
        let Some(name) = current else {
            return Err(error(
                path,
                card.line,
                "*SURFACE BEHAVIOR outside a *SURFACE INTERACTION",
            ));
        };
        let kind = required(path, card, "PRESSURE-OVERCLOSURE")?.to_ascii_uppercase();
        if card.data.len() > 1 {
            return Err(error(
                path,
                card.data[1].line,
                "*SURFACE BEHAVIOR takes one data line 'K[, σ∞, c0]'",
            ));
        }
        let values: Vec<f64> = match card.data.first() {
            None => Vec::new(),
            Some(d) => {
                if d.fields.len() > 3 {
                    return Err(error(path, d.line, "the line is 'K[, σ∞, c0]'"));
                }
                (0..d.fields.len())
                    .filter(|&k| !d.fields[k].is_empty())
                    .map(|k| num(path, d, k, "pressure-overclosure value"))
                    .collect::<Result<_>>()?
            }
        };
        let here = format!("{}:{}", path.display(), card.line);
        let law = match kind.as_str() {
            "HARD" => {
                self.warnings.push(format!(
                    "{here}: PRESSURE-OVERCLOSURE=HARD solved as hard contact (no penetration, \
                     no tension) exactly; ccx 2.20 replaces it by a linear penalty of slope K \
                     ({}), whose overclosure p/K rodstudy's solution does not have",
                    values.first().map_or(
                        "50 × the largest Young's modulus, its default".into(),
                        |k| { format!("{k}, as given") }
                    )
                ));
                ContactLaw::Hard
            }
            "LINEAR" => {
                let k = *values.first().ok_or_else(|| {
                    error(
                        path,
                        card.line,
                        "PRESSURE-OVERCLOSURE=LINEAR needs its slope: a line 'K[, σ∞, c0]'",
                    )
                })?;
                if k.is_nan() || k <= 0.0 {
                    return Err(error(
                        path,
                        card.data[0].line,
                        format!("the slope K = {k} of a linear contact law must be positive"),
                    ));
                }
                if values.len() > 1 {
                    self.warnings.push(format!(
                        "{here}: σ∞ and c0 of PRESSURE-OVERCLOSURE=LINEAR read and not used: \
                         σ∞ acts in ccx's node-to-surface contact only, and every slave node is \
                         paired with the master surface whatever its clearance"
                    ));
                }
                ContactLaw::Linear { k }
            }
            _ => {
                return Err(error(
                    path,
                    card.line,
                    format!("PRESSURE-OVERCLOSURE={kind} is not supported (HARD or LINEAR)"),
                ));
            }
        };
        let entry = self.interactions.get_mut(name).expect("read above");
        if entry.0.is_some() {
            return Err(error(
                path,
                card.line,
                format!("a second *SURFACE BEHAVIOR in interaction {name}"),
            ));
        }
        entry.0 = Some(law);
        Ok(())
    }

    pub(super) fn read_contact_pair(&mut self, path: &Path, card: &Card) -> Result<()> {
        let ty = card
            .param("TYPE")
            .unwrap_or("NODE TO SURFACE")
            .to_ascii_uppercase();
        if ty != "SURFACE TO SURFACE" {
            return Err(error(
                path,
                card.line,
                format!(
                    "*CONTACT PAIR, TYPE={ty} is not supported: TYPE=SURFACE TO SURFACE only \
                     (ccx's default is NODE TO SURFACE: give the TYPE)"
                ),
            ));
        }
        if card.has("ADJUST") {
            return Err(error(
                path,
                card.line,
                "*CONTACT PAIR, ADJUST (moving the slave nodes onto the master) is not supported",
            ));
        }
        let interaction = required(path, card, "INTERACTION")?.to_ascii_uppercase();
        match self.interactions.get(&interaction) {
            None => {
                return Err(error(
                    path,
                    card.line,
                    format!("surface interaction {interaction} is not defined above"),
                ));
            }
            Some((None, _)) => {
                return Err(error(
                    path,
                    card.line,
                    format!("surface interaction {interaction} has no *SURFACE BEHAVIOR"),
                ));
            }
            Some(_) => {}
        }
        for d in &card.data {
            if d.fields.len() != 2 {
                return Err(error(
                    path,
                    d.line,
                    "a *CONTACT PAIR line is 'slave surface, master surface'",
                ));
            }
            let mut names = Vec::new();
            for f in &d.fields {
                let name = f.to_ascii_uppercase();
                let faces = self.element_surfaces.get(&name).ok_or_else(|| {
                    error(
                        path,
                        d.line,
                        format!(
                            "surface {f} is not an element-face surface (*SURFACE, \
                             TYPE=ELEMENT): surface-to-surface contact needs faces on both sides"
                        ),
                    )
                })?;
                if let Some(&(e, _)) = faces
                    .iter()
                    .find(|(e, _)| self.elements[*e].nodes.len() != 10)
                {
                    return Err(error(
                        path,
                        d.line,
                        format!(
                            "surface {f} has faces of C3D4 element {}: contact is supported on \
                             C3D10 faces only",
                            self.elements[e].id
                        ),
                    ));
                }
                names.push(name);
            }
            self.contact_pairs.push(ContactPair {
                interaction: interaction.clone(),
                slave: names[0].clone(),
                master: names[1].clone(),
                line: d.line,
                file: card.file.clone(),
            });
        }
        Ok(())
    }
}
