//! The cards of a deck read into a [`Model`], keyword by keyword (the subset of `docs/solve.md`):
//! the dispatch, the parameters each keyword accepts, where it may stand, and the model-section
//! and step-structure keywords. Loads and supports are in [`super::load_cards`], output requests
//! in [`super::output_cards`], surfaces, local axes and equations in [`super::constraint_cards`].
//!
//! Every card is read even when an earlier one was refused, and every refusal is reported at
//! once, each with its file and line (a refusal that makes later cards meaningless, such as an
//! undefined set, is reported where it stands, and the cards that use it report their own line).

use std::collections::BTreeSet;
use std::path::Path;

use super::model::*;
use super::parse::{Card, error, int, num, required};
use crate::fem::error::{FemError, Result};

/// Parameters each keyword accepts (any other is refused).
fn allowed_params(keyword: &str) -> Option<&'static [&'static str]> {
    Some(match keyword {
        "HEADING" | "DENSITY" | "END STEP" => &[],
        "NODE" => &["NSET"],
        "ELEMENT" => &["TYPE", "ELSET"],
        "NSET" => &["NSET", "GENERATE"],
        "ELSET" => &["ELSET", "GENERATE"],
        "SURFACE" => &["NAME", "TYPE"],
        "TRANSFORM" => &["NSET", "TYPE"],
        "EQUATION" => &[],
        "MATERIAL" => &["NAME"],
        "ELASTIC" => &["TYPE"],
        "EXPANSION" => &["ZERO", "TYPE"],
        "PHYSICAL CONSTANTS" => &["ABSOLUTE ZERO", "STEFAN BOLTZMANN", "NEWTON GRAVITY"],
        "SOLID SECTION" => &["ELSET", "MATERIAL"],
        "BOUNDARY" => &["OP", "FIXED"],
        "CLOAD" | "DLOAD" | "DSLOAD" => &["OP"],
        "STEP" => &["INC", "INCF", "NLGEOM"],
        "STATIC" => &["SOLVER", "DIRECT"],
        "BUCKLE" => &["SOLVER"],
        "FREQUENCY" => &["SOLVER", "STORAGE", "GLOBAL", "CYCMPC"],
        "CONTROLS" => &["PARAMETERS", "RESET"],
        "OUTPUT" => &["FREQUENCY"],
        "NODE PRINT" => &["NSET", "TOTALS", "FREQUENCY", "GLOBAL"],
        "EL PRINT" => &["ELSET", "TOTALS", "FREQUENCY", "GLOBAL"],
        "NODE FILE" | "EL FILE" => &["FREQUENCY", "OUTPUT", "GLOBAL"],
        "SECTION PRINT" => &["SURFACE", "NAME", "FREQUENCY"],
        // ccx reads parameter names without their blanks
        "COUPLING" => &[
            "REF NODE",
            "REFNODE",
            "SURFACE",
            "CONSTRAINT NAME",
            "CONSTRAINTNAME",
            "ORIENTATION",
        ],
        "KINEMATIC" => &[],
        "SURFACE INTERACTION" => &["NAME"],
        "SURFACE BEHAVIOR" => &["PRESSURE-OVERCLOSURE"],
        "CONTACT PAIR" => &[
            "INTERACTION",
            "TYPE",
            "SMALL SLIDING",
            "SMALLSLIDING",
            "ADJUST",
        ],
        "CONTACT FILE" => &[
            "FREQUENCY",
            "OUTPUT",
            "GLOBAL",
            "TOTALS",
            "LAST ITERATIONS",
            "CONTACT ELEMENTS",
        ],
        "CONTACT PRINT" => &["FREQUENCY", "TOTALS", "TIME POINTS"],
        "DISTRIBUTING" => &["CYCLIC SYMMETRY", "CYCLICSYMMETRY"],
        _ => return None,
    })
}

/// What ccx does that rodstudy does not, for the message of a refused keyword.
fn why_refused(keyword: &str) -> &'static str {
    match keyword {
        "FRICTION" => "friction is not supported: frictionless contact only (remove *FRICTION)",
        "TIE" | "CONTACT OUTPUT" | "GAP" | "CLEARANCE" => {
            "only *CONTACT PAIR, TYPE=SURFACE TO SURFACE contact is supported"
        }
        "RIGID BODY" | "DISTRIBUTING COUPLING" => {
            "this coupling is not supported: use *COUPLING with *KINEMATIC or *DISTRIBUTING"
        }
        "PLASTIC" | "HYPERELASTIC" | "CREEP" | "DEFORMATION PLASTICITY" | "USER MATERIAL" => {
            "nonlinear materials are not supported (linear elastic only)"
        }
        "TEMPERATURE"
        | "INITIAL CONDITIONS"
        | "HEAT TRANSFER"
        | "COUPLED TEMPERATURE-DISPLACEMENT"
        | "CONDUCTIVITY"
        | "SPECIFIC HEAT"
        | "FILM"
        | "RADIATE"
        | "DFLUX"
        | "CFLUX" => "thermal analysis is not supported",
        "DYNAMIC" | "MODAL DYNAMIC" | "STEADY STATE DYNAMICS" | "VISCO" | "AMPLITUDE" => {
            "only *STATIC, *BUCKLE and *FREQUENCY steps are supported"
        }
        "SHELL SECTION" | "BEAM SECTION" | "MEMBRANE SECTION" => {
            "only solid elements (C3D10, C3D4) are supported"
        }
        "REFINE MESH" => "mesh refinement is not supported: refine the mesh before",
        "ORIENTATION" => "orientations (anisotropic materials) are not supported",
        _ => "see docs/solve.md for the keywords rodstudy reads",
    }
}

/// The state of the reading: the current material, the step being read and what its first
/// cards of a kind replace.
#[derive(Default)]
pub(super) struct Reader {
    pub(super) material: Option<String>,
    /// Supports and loads of the model section and of the steps so far.
    pub(super) state: Step,
    pub(super) in_step: bool,
    pub(super) steps_begun: usize,
    pub(super) first_cload: bool,
    pub(super) first_dload: bool,
    /// Loads given in the current step: a repeat within the step adds to them (as ccx does).
    pub(super) cloads_here: BTreeSet<(usize, usize)>,
    pub(super) pressures_here: BTreeSet<(usize, usize)>,
    pub(super) gravity_here: BTreeSet<usize>,
    pub(super) centrif_here: BTreeSet<usize>,
    pub(super) first_request: [bool; 4],
    pub(super) node_file: Vec<String>,
    pub(super) el_file: Vec<String>,
    /// A `*COUPLING` read, its `*KINEMATIC` or `*DISTRIBUTING` next: its reference node,
    /// surface and line.
    pub(super) coupling: Option<(usize, String, usize)>,
    /// The `*SURFACE INTERACTION` being read.
    pub(super) interaction: Option<String>,
}

/// Keywords of a step only.
const STEP_ONLY: &[&str] = &[
    "STATIC",
    "BUCKLE",
    "FREQUENCY",
    "CONTROLS",
    "CLOAD",
    "DLOAD",
    "DSLOAD",
    "NODE PRINT",
    "EL PRINT",
    "NODE FILE",
    "EL FILE",
    "SECTION PRINT",
    "OUTPUT",
    "CONTACT FILE",
    "CONTACT PRINT",
    "END STEP",
];

/// Keywords of the model section only.
const MODEL_ONLY: &[&str] = &[
    "NODE",
    "ELEMENT",
    "NSET",
    "ELSET",
    "SURFACE",
    "TRANSFORM",
    "EQUATION",
    "MATERIAL",
    "ELASTIC",
    "DENSITY",
    "EXPANSION",
    "PHYSICAL CONSTANTS",
    "SOLID SECTION",
    "STEP",
    "COUPLING",
    "KINEMATIC",
    "DISTRIBUTING",
    "SURFACE INTERACTION",
    "SURFACE BEHAVIOR",
    "CONTACT PAIR",
];

impl Model {
    /// Builds the model from the cards of `path`; all refusals at once.
    pub fn from_cards(path: &Path, cards: &[Card]) -> Result<Model> {
        let mut m = Model::default();
        let mut r = Reader::default();
        let mut refusals: Vec<FemError> = Vec::new();
        for card in cards {
            if let Err(e) = m.read_card(&card.file, card, &mut r) {
                refusals.push(e);
            }
        }
        if r.in_step {
            refusals.push(error(path, r.state.line, "*STEP without *END STEP"));
        }
        if let Some(p) = r.coupling.take() {
            refusals.push(error(
                path,
                p.2,
                "*COUPLING without its *KINEMATIC or *DISTRIBUTING card",
            ));
        }
        refusals.extend(m.finish_couplings());
        if refusals.is_empty() {
            if m.elements.is_empty() {
                refusals.push(error(
                    path,
                    0,
                    "no C3D10/C3D4 elements: a deck needs *NODE and *ELEMENT, TYPE=C3D10 (or \
                     C3D4) cards (an empty or cut-off file has none)",
                ));
            } else if m.steps.is_empty() {
                refusals.push(error(
                    path,
                    0,
                    "no *STEP: a deck needs a *STEP with *STATIC, *BUCKLE or *FREQUENCY, its \
                     loads and *END STEP",
                ));
            }
        }
        combine(refusals).map(|()| m)
    }

    fn read_card(&mut self, path: &Path, card: &Card, r: &mut Reader) -> Result<()> {
        let m = self;
        let kw = card.keyword.as_str();
        if !matches!(kw, "KINEMATIC" | "DISTRIBUTING")
            && let Some(p) = r.coupling.take()
        {
            return Err(error(
                path,
                p.2,
                "*COUPLING must be followed at once by *KINEMATIC or *DISTRIBUTING",
            ));
        }
        let Some(allowed) = allowed_params(kw) else {
            return Err(error(
                path,
                card.line,
                format!("*{kw} is not supported ({})", why_refused(kw)),
            ));
        };
        if let Some((p, _)) = card
            .params
            .iter()
            .find(|(p, _)| !allowed.contains(&p.as_str()))
        {
            return Err(error(
                path,
                card.line,
                format!("*{kw}: parameter {p} is not supported"),
            ));
        }
        if STEP_ONLY.contains(&kw) && !r.in_step {
            return Err(error(path, card.line, format!("*{kw} outside a *STEP")));
        }
        if r.in_step && MODEL_ONLY.contains(&kw) {
            return Err(error(
                path,
                card.line,
                format!("*{kw} inside a step (missing *END STEP?)"),
            ));
        }
        if kw != "SURFACE BEHAVIOR" {
            r.interaction = None;
        }
        if !matches!(kw, "ELASTIC" | "DENSITY" | "EXPANSION") {
            if kw != "MATERIAL" {
                r.material = None;
            }
        } else if r.material.is_none() {
            return Err(error(path, card.line, format!("*{kw} outside a *MATERIAL")));
        }
        let needs_data = matches!(
            kw,
            "NSET"
                | "ELSET"
                | "SURFACE"
                | "TRANSFORM"
                | "EQUATION"
                | "KINEMATIC"
                | "CONTACT PAIR"
                | "ELASTIC"
                | "DENSITY"
                | "BOUNDARY"
                | "CLOAD"
                | "DLOAD"
                | "DSLOAD"
                | "NODE PRINT"
                | "EL PRINT"
                | "BUCKLE"
                | "FREQUENCY"
        );
        if needs_data && card.data.is_empty() {
            return Err(error(path, card.line, format!("*{kw} without data lines")));
        }
        let max_data = match kw {
            "MATERIAL" | "STEP" | "END STEP" | "OUTPUT" | "PHYSICAL CONSTANTS" | "COUPLING" => 0,
            // a solid section may carry one data line (a thickness, unused for solids)
            "SOLID SECTION" | "STATIC" | "BUCKLE" | "FREQUENCY" | "TRANSFORM" => 1,
            _ => usize::MAX,
        };
        if card.data.len() > max_data {
            return Err(error(
                path,
                card.data[max_data].line,
                format!("*{kw} takes no further data lines"),
            ));
        }
        match kw {
            "HEADING" => Ok(()),
            "NODE" => m.read_nodes(path, card),
            "ELEMENT" => m.read_elements(path, card),
            "NSET" | "ELSET" => m.read_set(path, card),
            "SURFACE" => m.read_surface(path, card),
            "TRANSFORM" => m.read_transform(path, card),
            "EQUATION" => m.read_equation(path, card),
            "COUPLING" => m.read_coupling(path, card, r),
            "KINEMATIC" | "DISTRIBUTING" => m.read_coupling_kind(path, card, r),
            "SURFACE INTERACTION" => m.read_surface_interaction(path, card, &mut r.interaction),
            "SURFACE BEHAVIOR" => m.read_surface_behavior(path, card, &r.interaction),
            "CONTACT PAIR" => m.read_contact_pair(path, card),
            "CONTACT FILE" | "CONTACT PRINT" => {
                m.warnings.push(format!(
                    "{}:{}: *{kw} skipped: the contact pressures are in the JSON's `contact` \
                     block of the step",
                    path.display(),
                    card.line
                ));
                Ok(())
            }
            "MATERIAL" => {
                let name = required(path, card, "NAME")?.to_ascii_uppercase();
                if m.materials.contains_key(&name) {
                    return Err(error(
                        path,
                        card.line,
                        format!("material {name} defined twice"),
                    ));
                }
                m.materials.insert(
                    name.clone(),
                    MaterialDef {
                        line: card.line,
                        file: card.file.clone(),
                        ..Default::default()
                    },
                );
                r.material = Some(name);
                Ok(())
            }
            "ELASTIC" => {
                let (e, nu) = read_elastic(path, card)?;
                m.current_material(r).elastic = Some((e, nu));
                Ok(())
            }
            "DENSITY" => {
                let d = &card.data[0];
                if card.data.len() > 1 || d.fields.len() > 2 {
                    return Err(error(
                        path,
                        d.line,
                        "temperature-dependent density is not supported",
                    ));
                }
                let rho = num(path, d, 0, "density")?;
                if rho < 0.0 {
                    return Err(error(
                        path,
                        d.line,
                        format!("density {rho} is negative: a mass density is ≥ 0"),
                    ));
                }
                m.current_material(r).density = Some(rho);
                Ok(())
            }
            "EXPANSION" | "PHYSICAL CONSTANTS" => {
                m.warnings.push(format!(
                    "{}:{}: *{kw} read and not used: it acts only with temperatures, and \
                     thermal loads are not supported (none is given, so it changes nothing)",
                    path.display(),
                    card.line
                ));
                Ok(())
            }
            "SOLID SECTION" => {
                let elset = required(path, card, "ELSET")?.to_ascii_uppercase();
                let mat = required(path, card, "MATERIAL")?.to_ascii_uppercase();
                if !m.elsets.contains_key(&elset) {
                    return Err(error(
                        path,
                        card.line,
                        format!("element set {elset} is not defined"),
                    ));
                }
                m.sections.push(Section {
                    elset,
                    material: mat,
                    line: card.line,
                    file: card.file.clone(),
                });
                Ok(())
            }
            "BOUNDARY" => m.read_boundary(path, card, r),
            "CLOAD" => m.read_cload(path, card, r),
            "DLOAD" | "DSLOAD" => m.read_dload(path, card, r),
            "STEP" => {
                if let Some(v) = card.param("NLGEOM")
                    && !v.eq_ignore_ascii_case("NO")
                {
                    return Err(error(
                        path,
                        card.line,
                        "*STEP, NLGEOM: only linear analysis is supported (NLGEOM=NO)",
                    ));
                }
                r.in_step = true;
                r.steps_begun += 1;
                r.first_cload = true;
                r.first_dload = true;
                r.cloads_here.clear();
                r.pressures_here.clear();
                r.gravity_here.clear();
                r.centrif_here.clear();
                r.first_request = [true; 4];
                r.state.line = card.line;
                r.state.analysis = None;
                Ok(())
            }
            "STATIC" | "BUCKLE" | "FREQUENCY" => {
                if r.state.analysis.is_some() {
                    return Err(error(
                        path,
                        card.line,
                        "a second analysis card in one step: one of *STATIC, *BUCKLE, \
                         *FREQUENCY per step",
                    ));
                }
                r.state.analysis = Some(read_analysis(path, card, &mut m.warnings)?);
                Ok(())
            }
            "CONTROLS" => {
                m.warnings.push(format!(
                    "{}:{}: *CONTROLS read and not used: it tunes the increments and the \
                     equilibrium iterations of a nonlinear step; a linear step is solved in one \
                     increment without iterations, so it changes nothing",
                    path.display(),
                    card.line
                ));
                Ok(())
            }
            "OUTPUT" => {
                if let Some(f) = card.param("FREQUENCY") {
                    int(path, card.line, f, "FREQUENCY")?;
                }
                Ok(())
            }
            "NODE PRINT" | "EL PRINT" | "NODE FILE" | "EL FILE" => {
                m.read_output_request(path, card, r)
            }
            "SECTION PRINT" => {
                m.warnings.push(format!(
                    "{}:{}: *SECTION PRINT skipped: section forces and moments are not computed",
                    path.display(),
                    card.line
                ));
                Ok(())
            }
            "END STEP" => {
                if r.state.analysis.is_none() {
                    return Err(error(
                        path,
                        card.line,
                        "a step without *STATIC, *BUCKLE or *FREQUENCY",
                    ));
                }
                m.steps.push(r.state.clone());
                r.in_step = false;
                Ok(())
            }
            _ => unreachable!("allowed_params covers the keywords"),
        }
    }

    fn current_material(&mut self, r: &Reader) -> &mut MaterialDef {
        self.materials
            .get_mut(r.material.as_ref().expect("checked"))
            .expect("defined")
    }
}

/// All refusals as one error: the first's file and line, the others' each on a line of its own.
fn combine(mut refusals: Vec<FemError>) -> Result<()> {
    if refusals.is_empty() {
        return Ok(());
    }
    let n = refusals.len();
    let first = refusals.remove(0);
    if n == 1 {
        return Err(first);
    }
    match first {
        FemError::Parse {
            path,
            line,
            message,
        } => {
            let mut message = message;
            for e in refusals {
                message.push('\n');
                message.push_str(&e.to_string());
            }
            message.push_str(&format!("\n({n} refusals in all)"));
            Err(FemError::Parse {
                path,
                line,
                message,
            })
        }
        e => Err(e),
    }
}

fn read_elastic(path: &Path, card: &Card) -> Result<(f64, f64)> {
    if let Some(t) = card.param("TYPE")
        && !t.eq_ignore_ascii_case("ISO")
    {
        return Err(error(
            path,
            card.line,
            format!("*ELASTIC, TYPE={t}: only isotropic (TYPE=ISO) is supported"),
        ));
    }
    let d = &card.data[0];
    if card.data.len() > 1 || d.fields.len() > 3 {
        return Err(error(
            path,
            d.line,
            "temperature-dependent elastic constants are not supported",
        ));
    }
    let e = num(path, d, 0, "Young's modulus")?;
    let nu = num(path, d, 1, "Poisson's ratio")?;
    // a solid is stable (its strain energy positive) only for E > 0 and −1 < ν < 0.5
    if e <= 0.0 {
        return Err(error(
            path,
            d.line,
            format!(
                "Young's modulus {e} is not positive: no material has E ≤ 0; the line is 'E, ν'"
            ),
        ));
    }
    if !(nu > -1.0 && nu < 0.5) {
        return Err(error(
            path,
            d.line,
            format!(
                "Poisson's ratio {nu} lies outside (−1, 0.5), where no stable solid lies; the \
                 line is 'E, ν'"
            ),
        ));
    }
    Ok((e, nu))
}

/// `*STATIC` (its data line: increments, unused by a linear step), `*BUCKLE` (`modes[,
/// accuracy[, Lanczos vectors[, iterations]]]`), `*FREQUENCY` (`modes[, lower[, upper]]`).
fn read_analysis(path: &Path, card: &Card, warnings: &mut Vec<String>) -> Result<Analysis> {
    if let Some(s) = card.param("SOLVER") {
        // the solver of the linear equations: all give the same solution to round-off
        let known = [
            "SPOOLES",
            "PARDISO",
            "PASTIX",
            "SPARSE",
            "ITERATIVE SCALING",
            "ITERATIVE CHOLESKY",
            "DEFAULT",
        ];
        if !known.iter().any(|k| s.eq_ignore_ascii_case(k)) {
            return Err(error(
                path,
                card.line,
                format!("SOLVER={s}: unknown solver"),
            ));
        }
    }
    match card.keyword.as_str() {
        "STATIC" => {
            if card.has("DIRECT") {
                warnings.push(format!(
                    "{}:{}: *STATIC, DIRECT (fixed increments) changes nothing: a linear step \
                     is solved in one increment",
                    path.display(),
                    card.line
                ));
            }
            Ok(Analysis::Static)
        }
        "BUCKLE" => {
            let d = &card.data[0];
            if d.fields.len() > 4 {
                return Err(error(
                    path,
                    d.line,
                    "a *BUCKLE line is 'modes[, accuracy, ncv, iterations]'",
                ));
            }
            let modes = int(path, d.line, &d.fields[0], "number of buckling factors")?;
            if !(1..=100).contains(&modes) {
                return Err(error(
                    path,
                    d.line,
                    format!("{modes} buckling factors: ask for 1 to 100"),
                ));
            }
            let accuracy = match d.fields.get(1).filter(|f| !f.is_empty()) {
                Some(_) => num(path, d, 1, "accuracy")?,
                None => 0.01,
            };
            if !(accuracy > 0.0 && accuracy < 1.0) {
                return Err(error(
                    path,
                    d.line,
                    format!("accuracy {accuracy}: 0 < accuracy < 1"),
                ));
            }
            Ok(Analysis::Buckle {
                modes: modes as usize,
                accuracy,
            })
        }
        _ => {
            if card
                .param("STORAGE")
                .is_some_and(|v| !v.eq_ignore_ascii_case("NO"))
            {
                return Err(error(
                    path,
                    card.line,
                    "*FREQUENCY, STORAGE=YES is not supported",
                ));
            }
            if card
                .param("CYCMPC")
                .is_some_and(|v| !v.eq_ignore_ascii_case("INACTIVE"))
            {
                return Err(error(
                    path,
                    card.line,
                    "*FREQUENCY, CYCMPC: cyclic symmetry is not supported",
                ));
            }
            let d = card
                .data
                .first()
                .ok_or_else(|| error(path, card.line, "*FREQUENCY without its data line"))?;
            if d.fields.len() > 3 {
                return Err(error(
                    path,
                    d.line,
                    "a *FREQUENCY line is 'modes[, lower, upper]' (cycles/time)",
                ));
            }
            let modes = int(path, d.line, &d.fields[0], "number of frequencies")?;
            if !(1..=100).contains(&modes) {
                return Err(error(
                    path,
                    d.line,
                    format!("{modes} frequencies: ask for 1 to 100"),
                ));
            }
            let lower = match d.fields.get(1).filter(|f| !f.is_empty()) {
                Some(_) => num(path, d, 1, "lower frequency")?,
                None => 0.0,
            };
            if lower > 0.0 {
                warnings.push(format!(
                    "{}:{}: *FREQUENCY lower bound {lower} read as the shift: the lowest \
                     frequencies are computed and the step is refused if one is below it",
                    path.display(),
                    d.line
                ));
            }
            let upper = match d.fields.get(2).filter(|f| !f.is_empty()) {
                Some(_) => Some(num(path, d, 2, "upper frequency")?),
                None => None,
            };
            Ok(Analysis::Frequency {
                modes: modes as usize,
                lower,
                upper,
            })
        }
    }
}
