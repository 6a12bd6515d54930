//! Linear static, buckling and frequency analysis of a standard input deck: the subset of the
//! Abaqus/CalculiX `.inp` format a linear model of tetrahedra needs (the table of `docs/solve.md`) (`rodstudy solve DECK.inp`), so that the FEM
//! core can be run on the field's benchmarks (NAFEMS LE10: NAFEMS, "The Standard NAFEMS
//! Benchmarks", TNSB Rev. 3, 1990; `pipeline/nafems_le10.py`) and on a user's own CalculiX or
//! Abaqus model.
//!
//! * [`parse`]: lines into cards (keyword, parameters, data lines, line numbers);
//! * [`model`], read by [`cards`], [`mesh_cards`], [`load_cards`], [`output_cards`] and
//!   [`constraint_cards`]: nodes, C3D10/C3D4 elements, sets, surfaces, materials, sections, local
//!   axes, equations, supports, loads, output requests per step; every other keyword, parameter
//!   or data form is refused with its line number (all of a deck's at once), never ignored;
//! * [`system`] and [`solve`]: the element matrices, constraints and loads as ccx forms them, one
//!   static, buckling or frequency solve per step, node-set values, RF = K u, nodal stresses and
//!   strains ([`fields`]);
//! * [`output`]: the JSON document and the VTU files.
//!
//! Reference for the format and its semantics: the CalculiX CrunchiX user's manual (ccx 2.20),
//! "Input deck format" and the keyword sections; the element node order and face numbering from
//! its "C3D10" section. Deck units are kept as given (no conversion).

pub mod cards;
pub mod constraint_cards;
pub mod contact;
pub mod contact_cards;
pub mod coupling;
pub mod coupling_cards;
pub mod fields;
pub mod load_cards;
pub mod mesh_cards;
pub mod model;
pub mod output;
pub mod output_cards;
pub mod parse;
pub mod solve;
pub mod system;

use std::path::Path;

use crate::fem::error::{FemError, Result};
pub use model::Model;
pub use solve::{DeckSolution, SolveOptions, solve_model, solve_model_at};

/// Reads and checks the deck at `path`. A deck is ASCII in its cards; bytes that are not UTF-8
/// (a Latin-1 `é` in a `**` comment, as older pre-processors write) are read as U+FFFD, so that
/// a comment never matters and a data line holding one is refused with its line.
pub fn read_deck(path: &Path) -> Result<Model> {
    let bytes = std::fs::read(path).map_err(|e| FemError::Io {
        path: path.to_path_buf(),
        error: e,
    })?;
    read_deck_text(path, &String::from_utf8_lossy(&bytes))
}

/// Reads a deck from `text` (`path` names it in errors).
pub fn read_deck_text(path: &Path, text: &str) -> Result<Model> {
    let cards = parse::cards(path, text)?;
    Model::from_cards(path, &cards)
}
