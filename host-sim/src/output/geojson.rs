//! Edges as a GeoJSON FeatureCollection with the legacy `crs` member (docs/spec.md §3).

use super::features::{features, LineKind};
use crate::model::{Crs, EdgeLine, GeoJsonError, SCHEMA_MEMBER, SCHEMA_VERSION};

/// Serialises lines as a GeoJSON FeatureCollection with the legacy `crs` member: per
/// stretch its toe feature and, where surveyed, its top feature (`line`, `edge`).
pub fn lines_to_geojson(lines: &[EdgeLine], crs: Option<&Crs>) -> serde_json::Value {
    use serde_json::{json, Map, Value};
    let features: Vec<Value> = features(lines)
        .iter()
        .map(|f| {
            let l = f.stretch;
            let mut props = Map::new();
            props.insert("side".into(), json!(l.side.as_str()));
            if let Some(c) = l.category {
                props.insert("category".into(), json!(c.as_str()));
            }
            if let Some(m) = &l.method {
                props.insert("method".into(), json!(m));
            }
            props.insert("length_m".into(), json!(round_to(f.length_m(), 1e-3)));
            if let Some(h) = l.curb_height_m {
                props.insert("curb_height_m".into(), json!(round_to(h, 1e-4)));
            }
            if let Some(d) = &l.detail {
                props.insert("line".into(), json!(f.kind.as_str()));
                props.insert("edge".into(), json!(f.edge));
                // Reference lines (no method) are not extracted: no support to tell.
                if l.method.is_some() {
                    props.insert("bridged".into(), json!(d.bridged));
                    props.insert(
                        "support_per_m".into(),
                        json!(round_to(d.support_per_m, 1e-2)),
                    );
                }
                // Fused edges name the scanners and passes that contributed.
                for (key, ids) in [("scanners", d.scanners()), ("passes", d.passes())] {
                    if !ids.is_empty() {
                        props.insert(key.into(), json!(ids));
                    }
                }
                if f.kind == LineKind::Toe {
                    let hs: Vec<f64> = d.height_m.iter().map(|&h| round_to(h, 1e-4)).collect();
                    props.insert("heights_m".into(), json!(hs));
                }
            }
            let coords: Vec<Value> = f
                .points
                .iter()
                .map(|p| {
                    json!([
                        round_to(p[0], 1e-4),
                        round_to(p[1], 1e-4),
                        round_to(p[2], 1e-4)
                    ])
                })
                .collect();
            json!({
                "type": "Feature",
                "properties": Value::Object(props),
                "geometry": { "type": "LineString", "coordinates": coords },
            })
        })
        .collect();
    let mut fc = Map::new();
    fc.insert("type".into(), json!("FeatureCollection"));
    fc.insert(
        SCHEMA_MEMBER.into(),
        json!(format!("{}.{}", SCHEMA_VERSION.0, SCHEMA_VERSION.1)),
    );
    if let Some(crs) = crs {
        let name = match crs {
            Crs::Epsg(code) => format!("urn:ogc:def:crs:EPSG::{code}"),
            Crs::Wkt(wkt) => wkt.clone(),
        };
        fc.insert(
            "crs".into(),
            json!({ "type": "name", "properties": { "name": name } }),
        );
    }
    fc.insert("features".into(), Value::Array(features));
    Value::Object(fc)
}

/// `v` rounded to a multiple of `step` (a power of ten), dividing by the integer `1 / step`
/// so that the result is the nearest `f64` to the decimal (0.148, not 0.14800000000000002).
fn round_to(v: f64, step: f64) -> f64 {
    let inv = (1.0 / step).round();
    (v * inv).round() / inv
}

/// Writes lines to a GeoJSON file.
pub fn write_geojson(
    path: &std::path::Path,
    lines: &[EdgeLine],
    crs: Option<&Crs>,
) -> Result<(), GeoJsonError> {
    let v = lines_to_geojson(lines, crs);
    let text = serde_json::to_string(&v).map_err(|e| GeoJsonError::Format {
        path: path.display().to_string(),
        what: e.to_string(),
    })?;
    std::fs::write(path, text).map_err(|source| GeoJsonError::Io {
        path: path.display().to_string(),
        source,
    })
}
