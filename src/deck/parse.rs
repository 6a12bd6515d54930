//! Lines of an Abaqus/CalculiX input deck into cards: a keyword line (`*KEYWORD, PARAM=VALUE, ...`)
//! and its data lines, each with its 1-based line number.
//!
//! Syntax as in the CalculiX CrunchiX user's manual (ccx 2.20), "Input deck format": a line starting
//! with `*` is a keyword line, `**` a comment line; keywords and parameter names are
//! case-insensitive (upper-cased here), a keyword line ending with a comma continues on the next
//! line; data fields are separated by commas, blanks around them are not significant, and empty
//! trailing fields are dropped. Keywords of more than one word (`*SOLID SECTION`, `*NODE PRINT`)
//! are kept with one blank between the words. A UTF-8 byte-order mark before the first line is
//! skipped; a data line of empty fields only (`,,,`) is refused with its line (outside
//! `*HEADING`, whose lines are free text).
//!
//! `*INCLUDE, INPUT=FILE` reads FILE (relative to the including file's folder) in its place, as
//! ccx does (manual, "*INCLUDE"); its cards keep their own file and line for errors. An included
//! file starts with a keyword (its data lines cannot continue a card of the including file), and
//! an including file's data lines after an *INCLUDE are refused likewise; includes nest at most
//! [`MAX_INCLUDE_DEPTH`] deep.

use std::path::Path;

use crate::fem::error::{FemError, Result};

/// One data line: its line number and its comma-separated fields (trimmed).
#[derive(Clone, Debug, PartialEq)]
pub struct DataLine {
    /// 1-based line number.
    pub line: usize,
    /// The fields, trimmed, trailing empty ones dropped.
    pub fields: Vec<String>,
}

/// A keyword with its parameters and data lines.
#[derive(Clone, Debug, PartialEq)]
pub struct Card {
    /// Upper-cased keyword without the `*`, words separated by one blank.
    pub keyword: String,
    /// Parameters: upper-cased name and value as written (empty when the parameter has none).
    pub params: Vec<(String, String)>,
    /// 1-based line number of the keyword line.
    pub line: usize,
    /// The file the card is written in (the deck, or a file it includes).
    pub file: std::path::PathBuf,
    /// The data lines that follow.
    pub data: Vec<DataLine>,
}

impl Card {
    /// The value of parameter `name` (upper case), if given.
    pub fn param(&self, name: &str) -> Option<&str> {
        self.params
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// True when parameter `name` is given (with or without a value).
    pub fn has(&self, name: &str) -> bool {
        self.params.iter().any(|(k, _)| k == name)
    }
}

/// A parse error at `line` of `path`.
pub fn error(path: &Path, line: usize, message: impl Into<String>) -> FemError {
    FemError::Parse {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

/// How deep `*INCLUDE`s may nest (a file including itself is refused there).
pub const MAX_INCLUDE_DEPTH: usize = 16;

/// Splits `text` into cards, `*INCLUDE`s read in place. Data lines before the first keyword are
/// an error.
pub fn cards(path: &Path, text: &str) -> Result<Vec<Card>> {
    let mut out = Vec::new();
    cards_into(path, text, 0, &mut out)?;
    Ok(out)
}

fn cards_into(path: &Path, text: &str, depth: usize, out: &mut Vec<Card>) -> Result<()> {
    let start = out.len();
    // the card that data lines continue: none right after an *INCLUDE
    let mut open = false;
    let mut continuing = false;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for (i, raw) in text.lines().enumerate() {
        let ln = i + 1;
        let t = raw.trim();
        if t.is_empty() || t.starts_with("**") {
            continue;
        }
        if continuing {
            // continuation of the previous keyword line's parameters
            continuing = t.ends_with(',');
            let card = out.last_mut().expect("continuing a card");
            card.params.extend(params(t));
            if !continuing && card.keyword == "INCLUDE" {
                include(path, depth, out)?;
                open = false;
            }
            continue;
        }
        if let Some(rest) = t.strip_prefix('*') {
            continuing = rest.ends_with(',');
            let mut parts = rest.splitn(2, ',');
            let keyword = parts
                .next()
                .unwrap_or("")
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" ")
                .to_ascii_uppercase();
            if keyword.is_empty() {
                return Err(error(path, ln, "a keyword line without a keyword"));
            }
            out.push(Card {
                keyword,
                params: params(parts.next().unwrap_or("")),
                line: ln,
                file: path.to_path_buf(),
                data: Vec::new(),
            });
            open = true;
            if !continuing && out.last().is_some_and(|c| c.keyword == "INCLUDE") {
                include(path, depth, out)?;
                open = false;
            }
            continue;
        }
        if !open {
            return Err(error(
                path,
                ln,
                if out.len() > start {
                    "a data line after *INCLUDE: start the data with its keyword line again"
                } else {
                    "a data line before the first keyword (an included file starts with a keyword)"
                },
            ));
        }
        let card = out.last_mut().expect("an open card");
        let mut fields: Vec<String> = t.split(',').map(|f| f.trim().to_string()).collect();
        while fields.last().is_some_and(|f| f.is_empty()) {
            fields.pop();
        }
        if fields.is_empty() && card.keyword != "HEADING" {
            return Err(error(
                path,
                ln,
                format!(
                    "a data line of *{} without data (`{t}`): remove it or fill in its fields",
                    card.keyword
                ),
            ));
        }
        card.data.push(DataLine { line: ln, fields });
    }
    Ok(())
}

/// Replaces the `*INCLUDE` card at the end of `out` by the cards of its file.
fn include(path: &Path, depth: usize, out: &mut Vec<Card>) -> Result<()> {
    let card = out.pop().expect("the *INCLUDE card");
    let Some(name) = card.param("INPUT").filter(|v| !v.is_empty()) else {
        return Err(error(path, card.line, "*INCLUDE needs INPUT=FILE"));
    };
    if let Some((p, _)) = card.params.iter().find(|(p, _)| p != "INPUT") {
        return Err(error(
            path,
            card.line,
            format!("*INCLUDE: parameter {p} is not supported (INPUT=)"),
        ));
    }
    if depth >= MAX_INCLUDE_DEPTH {
        return Err(error(
            path,
            card.line,
            format!(
                "*INCLUDE nested deeper than {MAX_INCLUDE_DEPTH} files (a file including itself?)"
            ),
        ));
    }
    let name = name.trim_matches('"');
    let file = path.parent().unwrap_or(Path::new(".")).join(name);
    let bytes = std::fs::read(&file).map_err(|e| {
        error(
            path,
            card.line,
            format!("*INCLUDE: cannot read {}: {e}", file.display()),
        )
    })?;
    cards_into(&file, &String::from_utf8_lossy(&bytes), depth + 1, out)
}

fn params(s: &str) -> Vec<(String, String)> {
    s.split(',')
        .map(str::trim)
        .filter(|p| !p.is_empty())
        .map(|p| {
            let (k, v) = p.split_once('=').unwrap_or((p, ""));
            (k.trim().to_ascii_uppercase(), v.trim().to_string())
        })
        .collect()
}

pub(super) fn num(path: &Path, d: &DataLine, k: usize, what: &str) -> Result<f64> {
    let f = d
        .fields
        .get(k)
        .ok_or_else(|| error(path, d.line, format!("missing {what} (field {})", k + 1)))?;
    // Fortran-style exponents (1.0D+03) are accepted as ccx accepts them
    // Rust's parser also reads "nan", "inf" and overflows to infinity: refused, as ccx would
    // refuse them or carry them into the solution
    f.replace(['d', 'D'], "e")
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| {
            error(
                path,
                d.line,
                format!("{what}: '{f}' is not a finite number"),
            )
        })
}

/// Largest magnitude of a load value (force, pressure, gravity): beyond any load in any
/// consistent units, and where the solution's norms (squares of the loads) leave f64's range.
pub const MAX_LOAD: f64 = 1e100;

/// Field `k` of `d` as a load value: finite and at most [`MAX_LOAD`] in magnitude.
pub(super) fn load(path: &Path, d: &DataLine, k: usize, what: &str) -> Result<f64> {
    let v = num(path, d, k, what)?;
    if v.abs() > MAX_LOAD {
        return Err(error(
            path,
            d.line,
            format!(
                "{what} {v:e} is beyond any load (|value| ≤ {MAX_LOAD:e} in any units) and \
                 overflows the solution: check the value and its units"
            ),
        ));
    }
    Ok(v)
}

/// Largest magnitude of a node coordinate: beyond any model in any units (1e12 mm is a million
/// kilometres), where the elements' stiffness leaves f64's precision.
pub const MAX_COORDINATE: f64 = 1e12;

/// Field `k` of `d` as a node coordinate: finite and at most [`MAX_COORDINATE`] in magnitude.
pub(super) fn coordinate(path: &Path, d: &DataLine, k: usize, what: &str) -> Result<f64> {
    let v = num(path, d, k, what)?;
    if v.abs() > MAX_COORDINATE {
        return Err(error(
            path,
            d.line,
            format!(
                "{what} {v:e} is beyond any model (|coordinate| ≤ {MAX_COORDINATE:e} in any \
                 units): check the value and its units"
            ),
        ));
    }
    Ok(v)
}

pub(super) fn int(path: &Path, line: usize, f: &str, what: &str) -> Result<i64> {
    f.parse()
        .map_err(|_| error(path, line, format!("{what}: '{f}' is not an integer")))
}

pub(super) fn required<'a>(path: &Path, card: &'a Card, name: &str) -> Result<&'a str> {
    match card.param(name) {
        Some(v) if !v.is_empty() => Ok(v),
        _ => Err(error(
            path,
            card.line,
            format!("*{} needs {name}=", card.keyword),
        )),
    }
}

pub(super) fn push_unique(set: &mut Vec<usize>, items: impl IntoIterator<Item = usize>) {
    for i in items {
        if !set.contains(&i) {
            set.push(i);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keywords_params_data_and_lines() {
        let text = "** c\n*Node, nset=ALL\n1, 0, 0, 0\n\n*solid   section, elset=E,\n material=M\n*END STEP\n";
        let c = cards(Path::new("x.inp"), text).unwrap();
        assert_eq!(c.len(), 3);
        assert_eq!(c[0].keyword, "NODE");
        assert_eq!(c[0].param("NSET"), Some("ALL"));
        assert_eq!(c[0].data[0].line, 3);
        assert_eq!(c[0].data[0].fields, ["1", "0", "0", "0"]);
        assert_eq!(c[1].keyword, "SOLID SECTION");
        assert_eq!(c[1].line, 5);
        assert_eq!(c[1].param("MATERIAL"), Some("M"));
        assert_eq!(c[2].keyword, "END STEP");
    }
}
