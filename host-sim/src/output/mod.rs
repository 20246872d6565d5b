//! Sinks: writers of the extracted edges, one file per format.

pub mod csv;
pub mod geojson;
