//! Edges as FlatGeobuf: one layer `edges` of LineString Z features (toe and top lines,
//! told apart by `line`) with a packed Hilbert
//! R-tree (none when there are no edges), the LAS CRS in the header (EPSG code, and the WKT when the LAS gives one),
//! written by the `flatgeobuf` crate.

use super::features::features;
use super::format::{OutputError, OutputFormat};
use crate::model::{Crs, EdgeLine, SCHEMA_MEMBER, SCHEMA_VERSION};
use flatgeobuf::geozero::{ColumnValue, FeatureProcessor, GeomProcessor, PropertyProcessor};
use flatgeobuf::{ColumnType, FgbCrs, FgbWriter, FgbWriterOptions, GeometryType};
use std::io::Write;
use std::path::Path;

/// The layer name.
pub const LAYER: &str = "edges";

/// The attribute columns, in file order.
const COLUMNS: [(&str, ColumnType, bool); 11] = [
    ("side", ColumnType::String, false),
    ("method", ColumnType::String, true),
    ("length_m", ColumnType::Double, false),
    ("curb_height_m", ColumnType::Double, true),
    ("category", ColumnType::String, true),
    ("line", ColumnType::String, false),
    ("edge", ColumnType::Long, false),
    ("bridged", ColumnType::Bool, true),
    ("support_per_m", ColumnType::Double, true),
    ("scanners", ColumnType::String, true),
    ("passes", ColumnType::String, true),
];

/// Writes `edges` as FlatGeobuf at `path`, replacing any file there.
pub fn write_fgb(path: &Path, edges: &[EdgeLine], crs: Option<&Crs>) -> Result<(), OutputError> {
    let enc =
        |e: geozero::error::GeozeroError| OutputError::encode(path, OutputFormat::FlatGeobuf, e);
    let fgb_err = |e: flatgeobuf::Error| OutputError::encode(path, OutputFormat::FlatGeobuf, e);
    let wkt = match crs {
        Some(Crs::Wkt(w)) => Some(w.as_str()),
        _ => None,
    };
    let code = crs
        .and_then(Crs::epsg_code)
        .and_then(|c| i32::try_from(c).ok());
    let description = format!(
        "curbtrace road edges, {SCHEMA_MEMBER} {}.{}",
        SCHEMA_VERSION.0, SCHEMA_VERSION.1
    );
    let options = FgbWriterOptions {
        // The crate declares an index even for no features, which readers refuse.
        write_index: !edges.is_empty(),
        detect_type: false,
        promote_to_multi: false,
        has_z: true,
        crs: FgbCrs {
            // A code of 0 means "unknown"; the organisation defaults to EPSG.
            code: code.unwrap_or(0),
            wkt,
            ..Default::default()
        },
        description: Some(&description),
        ..Default::default()
    };
    let mut fgb = FgbWriter::create_with_options(LAYER, GeometryType::LineString, options)
        .map_err(fgb_err)?;
    for (name, ty, nullable) in COLUMNS {
        fgb.add_column(name, ty, |_, col| col.nullable = nullable);
    }
    for (i, f) in features(edges).iter().enumerate() {
        let e = f.stretch;
        let (scanners, passes) = (f.scanners(), f.passes());
        let props = [
            Some(ColumnValue::String(e.side.as_str())),
            e.method.as_deref().map(ColumnValue::String),
            Some(ColumnValue::Double(f.length_m())),
            e.curb_height_m.map(ColumnValue::Double),
            e.category.map(|c| ColumnValue::String(c.as_str())),
            Some(ColumnValue::String(f.kind.as_str())),
            Some(ColumnValue::Long(f.edge as i64)),
            f.bridged().map(ColumnValue::Bool),
            f.support_per_m().map(ColumnValue::Double),
            scanners.as_deref().map(ColumnValue::String),
            passes.as_deref().map(ColumnValue::String),
        ];
        for (k, value) in props.iter().enumerate() {
            if let Some(v) = value {
                fgb.property(k, COLUMNS[k].0, v).map_err(enc)?;
            }
        }
        fgb.linestring_begin(true, f.points.len(), 0).map_err(enc)?;
        for (j, p) in f.points.iter().enumerate() {
            fgb.coordinate(p[0], p[1], Some(p[2]), None, None, None, j)
                .map_err(enc)?;
        }
        fgb.linestring_end(true, 0).map_err(enc)?;
        fgb.feature_end(i as u64).map_err(enc)?;
    }
    let file = std::fs::File::create(path).map_err(|e| OutputError::io(path, e))?;
    let mut out = std::io::BufWriter::new(file);
    fgb.write(&mut out).map_err(fgb_err)?;
    out.flush().map_err(|e| OutputError::io(path, e))
}
