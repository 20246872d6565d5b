//! Output sinks: the edges written as GeoJSON, CSV, GeoPackage, FlatGeobuf or DXF, chosen by
//! the extension of the output path (`docs/output-formats.md`).

pub mod dxf;
pub mod fgb;
pub mod format;
pub mod gpkg;
