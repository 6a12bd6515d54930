//! Output requests of a deck: `*NODE PRINT` (U, S, E, RF; TOTALS=NO|YES|ONLY), `*EL PRINT` (S, E
//! at the integration points), `*NODE FILE` / `*EL FILE` (the fields of the VTU file). FREQUENCY=0
//! switches a request off (ccx: no output of that kind); any other FREQUENCY writes the step's
//! result (a linear step has one increment). Output variables ccx knows and rodstudy does not
//! compute (plastic strain, energy, contact, thermal fields, …) are skipped with a warning; an
//! unknown name is refused.

use std::path::Path;

use super::cards::Reader;
use super::model::*;
use super::parse::{Card, error, int, required};
use crate::fem::error::Result;

/// ccx output variables that are not computed here (skipped with a warning).
const NOT_COMPUTED: &[&str] = &[
    "NOE", "PEEQ", "ENER", "ELSE", "ELKE", "EVOL", "EMAS", "CSTR", "CDIS", "CELS", "SDV", "HFL",
    "NT", "TT", "RFL", "FLUX", "CF", "PU", "PNT", "PHS", "MF", "MAXU", "MAXS", "MAXE", "ZZS",
    "ERR", "HER", "SF", "SVF", "V", "VF", "PS", "PSF", "PT", "PTF", "TS", "TSF", "DEPF", "SEN",
    "MACH", "CP", "TURB", "EBHE", "KEQ", "ECD", "POT", "EMFB", "EMFE", "ME", "PE", "SNEG",
];

impl Model {
    pub(super) fn read_output_request(
        &mut self,
        path: &Path,
        card: &Card,
        r: &mut Reader,
    ) -> Result<()> {
        let kw = card.keyword.as_str();
        let mut vars = Vec::new();
        for d in &card.data {
            for f in &d.fields {
                let v = f.to_ascii_uppercase();
                let ok = match kw {
                    "EL PRINT" | "EL FILE" => matches!(v.as_str(), "S" | "E"),
                    _ => matches!(v.as_str(), "U" | "S" | "E" | "RF"),
                };
                if !ok {
                    if NOT_COMPUTED.contains(&v.as_str())
                        || matches!(v.as_str(), "U" | "RF" | "S" | "E")
                    {
                        self.warnings.push(format!(
                            "{}:{}: *{kw} {v} skipped: not computed by rodstudy solve \
                             (*NODE PRINT/*NODE FILE: U, S, E, RF; *EL PRINT/*EL FILE: S, E)",
                            path.display(),
                            d.line
                        ));
                        continue;
                    }
                    return Err(error(
                        path,
                        d.line,
                        format!("*{kw}: output variable '{f}' is not known (U, S, E, RF)"),
                    ));
                }
                if !vars.contains(&v) {
                    vars.push(v);
                }
            }
        }
        let off = match card.param("FREQUENCY") {
            Some(f) => {
                let n = int(path, card.line, f, "FREQUENCY")?;
                if n < 0 {
                    return Err(error(path, card.line, format!("FREQUENCY={n} is negative")));
                }
                n == 0
            }
            None => false,
        };
        let totals = match card.param("TOTALS") {
            None => Totals::No,
            Some(t) if t.eq_ignore_ascii_case("NO") => Totals::No,
            Some(t) if t.eq_ignore_ascii_case("YES") => Totals::Yes,
            Some(t) if t.eq_ignore_ascii_case("ONLY") => Totals::Only,
            Some(t) => {
                return Err(error(
                    path,
                    card.line,
                    format!("TOTALS={t}: NO, YES or ONLY"),
                ));
            }
        };
        if kw == "EL PRINT" && totals != Totals::No {
            return Err(error(
                path,
                card.line,
                "*EL PRINT, TOTALS (sums over elements, e.g. of energies) is not supported",
            ));
        }
        // ccx prints the values of a node with local axes (*TRANSFORM) in them unless
        // GLOBAL=YES; rodstudy prints global components only, so it asks for GLOBAL=YES there.
        // Totals alone (TOTALS=ONLY, as FreeCAD writes for its constraints) ccx sums in global
        // axes.
        if kw == "NODE PRINT"
            && totals != Totals::Only
            && card.param("GLOBAL").is_none()
            && let Some(set) = card.param("NSET")
            && let Some(nodes) = self.nsets.get(&set.to_ascii_uppercase())
            && nodes.iter().any(|n| self.transforms.contains_key(n))
        {
            return Err(error(
                path,
                card.line,
                "*NODE PRINT of nodes with local axes (*TRANSFORM): ccx prints them in the local \
                 axes by default, rodstudy in global axes only: add GLOBAL=YES",
            ));
        }
        if let Some(g) = card.param("GLOBAL")
            && !g.eq_ignore_ascii_case("YES")
        {
            return Err(error(
                path,
                card.line,
                format!(
                    "*{kw}, GLOBAL={g}: results in local axes are not supported (GLOBAL=YES: \
                     global axes)"
                ),
            ));
        }
        if let Some(o) = card.param("OUTPUT")
            && !(o.eq_ignore_ascii_case("2D") || o.eq_ignore_ascii_case("3D"))
        {
            return Err(error(path, card.line, format!("OUTPUT={o}: 2D or 3D")));
        }
        let kind = ["NODE PRINT", "EL PRINT", "NODE FILE", "EL FILE"]
            .iter()
            .position(|k| *k == kw)
            .expect("one of the four");
        if std::mem::replace(&mut r.first_request[kind], false) {
            match kind {
                0 => r.state.node_print.clear(),
                1 => r.state.el_print.clear(),
                2 => r.node_file.clear(),
                _ => r.el_file.clear(),
            }
        }
        match kw {
            "NODE PRINT" => {
                let set = required(path, card, "NSET")?.to_ascii_uppercase();
                if !self.nsets.contains_key(&set) {
                    return Err(error(
                        path,
                        card.line,
                        format!("node set {set} is not defined"),
                    ));
                }
                if !off {
                    r.state.node_print.push((set, vars, totals));
                }
            }
            "EL PRINT" => {
                let set = required(path, card, "ELSET")?.to_ascii_uppercase();
                if !self.elsets.contains_key(&set) {
                    return Err(error(
                        path,
                        card.line,
                        format!("element set {set} is not defined"),
                    ));
                }
                if !off {
                    r.state.el_print.push((set, vars));
                }
            }
            _ => {
                let list = if kind == 2 {
                    &mut r.node_file
                } else {
                    &mut r.el_file
                };
                if !off {
                    for v in vars {
                        if !list.contains(&v) {
                            list.push(v);
                        }
                    }
                }
            }
        }
        r.state.file_vars = r.node_file.clone();
        for v in &r.el_file {
            if !r.state.file_vars.contains(v) {
                r.state.file_vars.push(v.clone());
            }
        }
        Ok(())
    }
}
