//! Output sinks: the edges written as GeoJSON, CSV, GeoPackage, FlatGeobuf or DXF, chosen by
//! the extension of the output path (`docs/output-formats.md`).

pub mod csv;
pub mod dxf;
pub mod features;
pub mod fgb;
pub mod format;
pub mod geojson;
pub mod gpkg;

use crate::model::{Crs, EdgeLine};
use format::{OutputError, OutputFormat};
use std::path::Path;

/// Writes `edges` to `path` in the format its extension names (see [`OutputFormat::from_path`]).
pub fn write_edges(path: &Path, edges: &[EdgeLine], crs: Option<&Crs>) -> Result<(), OutputError> {
    write_edges_as(OutputFormat::from_path(path)?, path, edges, crs)
}

/// Writes `edges` to `path` in `format`, whatever the extension.
pub fn write_edges_as(
    format: OutputFormat,
    path: &Path,
    edges: &[EdgeLine],
    crs: Option<&Crs>,
) -> Result<(), OutputError> {
    match format {
        OutputFormat::GeoJson => Ok(geojson::write_geojson(path, edges, crs)?),
        OutputFormat::Csv => csv::write_edges(path, edges).map_err(|e| OutputError::io(path, e)),
        OutputFormat::GeoPackage => gpkg::write_gpkg(path, edges, crs),
        OutputFormat::FlatGeobuf => fgb::write_fgb(path, edges, crs),
        OutputFormat::Dxf => dxf::write_dxf(path, edges, crs),
    }
}
