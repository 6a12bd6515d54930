//! Everything that writes the study's output for people to look at; so far the stress pictures
//! ([`picture`]: a nodal field of a tet10 mesh drawn on its surface as a self-contained SVG). The
//! mathematics stays in [`crate::fem`], which opens no file.

pub mod picture;
