//! Output sinks: the edges written as GeoJSON, CSV, GeoPackage, FlatGeobuf or DXF, chosen by
//! the extension of the output path (`docs/output-formats.md`).

pub mod csv;
pub mod dxf;
pub mod fgb;
pub mod format;
pub mod geojson;
pub mod gpkg;
