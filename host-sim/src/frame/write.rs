//! Curb polylines of frames as GeoJSON or CSV, in each frame's sensor frame (docs/frames.md,
//! *Output*).
//!
//! - GeoJSON: one FeatureCollection; one LineString Feature per polyline with properties
//!   `frame` (the input file), `side`, `height_m`, `vertices`, `length_m`, and
//!   `coordinates: "sensor"`. The collection's own `properties` say that the coordinates are
//!   local: metres in the sensor frame (x ahead, y left, z up, origin at the sensor), no CRS
//!   (there is no `crs` member).
//! - CSV: `frame,line,side,height_m,vertex,x,y,z`, one row per vertex.

use super::CurbLine;
use serde_json::{json, Value};
use std::io::Write;
use std::path::Path;

/// What the GeoJSON says about its coordinates.
pub const FRAME_NOTE: &str = "local sensor frame, no CRS: metres, x ahead, y left, z up, origin at the lidar; one frame per 'frame' property";

fn r4(v: f64) -> f64 {
    (v * 1e4).round() / 1e4
}

/// The polylines of several frames (`(frame name, lines)`) as a GeoJSON FeatureCollection.
pub fn to_geojson(frames: &[(String, Vec<CurbLine>)]) -> Value {
    let mut features = Vec::new();
    for (name, lines) in frames {
        for l in lines {
            let coords: Vec<Value> = l
                .points
                .iter()
                .map(|p| json!([r4(p[0]), r4(p[1]), r4(p[2])]))
                .collect();
            features.push(json!({
                "type": "Feature",
                "properties": {
                    "frame": name,
                    "side": l.side.as_str(),
                    "height_m": r4(l.height_m),
                    "vertices": l.points.len(),
                    "length_m": r4(l.length_m()),
                    "coordinates": "sensor",
                },
                "geometry": { "type": "LineString", "coordinates": coords },
            }));
        }
    }
    json!({
        "type": "FeatureCollection",
        "properties": { "coordinates": FRAME_NOTE },
        "features": features,
    })
}

/// Writes GeoJSON (`.geojson`/`.json`) or CSV (`.csv`), chosen by `path`'s extension.
pub fn write(path: &Path, frames: &[(String, Vec<CurbLine>)]) -> std::io::Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let f = std::fs::File::create(path)?;
    let mut w = std::io::BufWriter::new(f);
    if ext == "csv" {
        writeln!(w, "frame,line,side,height_m,vertex,x,y,z")?;
        for (name, lines) in frames {
            for (k, l) in lines.iter().enumerate() {
                for (v, p) in l.points.iter().enumerate() {
                    writeln!(
                        w,
                        "{},{k},{},{:.4},{v},{:.4},{:.4},{:.4}",
                        csv_field(name),
                        l.side.as_str(),
                        l.height_m,
                        p[0],
                        p[1],
                        p[2]
                    )?;
                }
            }
        }
    } else {
        serde_json::to_writer_pretty(&mut w, &to_geojson(frames))?;
        writeln!(w)?;
    }
    w.flush()
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Side;

    fn line() -> CurbLine {
        CurbLine {
            side: Side::Left,
            points: vec![[1.0, 5.0, -1.7], [4.0, 5.1, -1.7]],
            height_m: 0.0912,
            steps_m: vec![0.09, 0.0912],
        }
    }

    #[test]
    fn geojson_says_it_is_local_and_csv_has_a_row_per_vertex() {
        let frames = vec![("a,b.bin".to_string(), vec![line()])];
        let g = to_geojson(&frames);
        assert!(g.get("crs").is_none());
        assert!(g["properties"]["coordinates"]
            .as_str()
            .unwrap()
            .contains("no CRS"));
        let f = &g["features"][0];
        assert_eq!(f["properties"]["side"], "left");
        assert_eq!(f["properties"]["height_m"], 0.0912);
        assert_eq!(f["geometry"]["coordinates"][1], json!([4.0, 5.1, -1.7]));
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("o.csv");
        write(&p, &frames).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        let rows: Vec<&str> = text.lines().collect();
        assert_eq!(rows[0], "frame,line,side,height_m,vertex,x,y,z");
        assert_eq!(rows[2], "\"a,b.bin\",0,left,0.0912,1,4.0000,5.1000,-1.7000");
        let q = dir.path().join("o.geojson");
        write(&q, &frames).unwrap();
        let back: Value = serde_json::from_str(&std::fs::read_to_string(&q).unwrap()).unwrap();
        assert_eq!(back, g);
    }
}
