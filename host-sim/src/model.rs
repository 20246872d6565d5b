//! Shared types of the host side: sides, categories, polylines and edges, and reading their
//! GeoJSON form (docs/spec.md §3; writing is in `output`). Everything in world coordinates is `f64`.

use serde::{Deserialize, Serialize};

/// Left or right relative to the driving direction (docs/spec.md §2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// Left of the driving direction (x′ > 0).
    Left,
    /// Right of the driving direction (x′ < 0).
    Right,
}

impl Side {
    /// The GeoJSON spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }
}

/// What kind of road edge a line is (docs/spec.md §3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Category {
    /// A plain curb.
    Curb,
    /// A lowered curb (driveway, crossing): 20–30 mm step.
    CurbCut,
    /// An intersection corner where the curb turns.
    Intersection,
    /// A bus bay, not parallel to the trajectory.
    BusBay,
}

impl Category {
    /// All categories, in table order.
    pub const ALL: [Category; 4] = [
        Category::Curb,
        Category::CurbCut,
        Category::Intersection,
        Category::BusBay,
    ];

    /// The GeoJSON spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Category::Curb => "curb",
            Category::CurbCut => "curb_cut",
            Category::Intersection => "intersection",
            Category::BusBay => "bus_bay",
        }
    }

    /// Parses the GeoJSON spelling.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.as_str() == s)
    }
}

/// A coordinate reference system as carried in the legacy GeoJSON `crs` member.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Crs {
    /// An EPSG code.
    Epsg(u32),
    /// OGC WKT.
    Wkt(String),
}

impl Crs {
    /// The EPSG code: the code itself, or the root `AUTHORITY["EPSG","N"]` of a WKT (the
    /// last AUTHORITY in WKT1 belongs to the outermost object).
    pub fn epsg_code(&self) -> Option<u32> {
        match self {
            Crs::Epsg(c) => Some(*c),
            Crs::Wkt(w) => {
                let i = w.rfind("AUTHORITY[")?;
                let rest = &w[i + "AUTHORITY[".len()..];
                let mut parts = rest.split(',');
                let auth = parts.next()?.trim().trim_matches('"');
                let code = parts.next()?.trim().trim_end_matches(']').trim_matches('"');
                if !auth.eq_ignore_ascii_case("EPSG") {
                    return None;
                }
                // The root AUTHORITY closes the whole WKT: only `]` may follow it.
                let after = rest.find(']').map(|k| &rest[k + 1..])?;
                if !after.chars().all(|c| c == ']' || c.is_whitespace()) {
                    return None;
                }
                code.parse().ok()
            }
        }
    }

    /// True when both name the same CRS: equal, or the same EPSG code.
    pub fn same_as(&self, other: &Crs) -> bool {
        self == other
            || matches!((self.epsg_code(), other.epsg_code()), (Some(a), Some(b)) if a == b)
    }
}

/// A road-edge line (extracted or reference) in world coordinates, with its properties.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeLine {
    /// Vertices `[x, y, z]` in the LAS CRS (z may be NaN-free 0.0 when the source was 2D).
    pub points: Vec<[f64; 3]>,
    /// Side relative to the driving direction.
    pub side: Side,
    /// Category where known.
    pub category: Option<Category>,
    /// Method that produced it (`bend`, `qiu`), `None` for reference lines.
    pub method: Option<String>,
    /// Median height step across the edge, metres, where known.
    pub curb_height_m: Option<f64>,
}

impl EdgeLine {
    /// Horizontal (2D) length in metres.
    pub fn length_m(&self) -> f64 {
        self.points
            .windows(2)
            .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt())
            .sum()
    }
}

/// Errors reading or writing GeoJSON line files.
#[derive(Debug, thiserror::Error)]
pub enum GeoJsonError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not GeoJSON of the expected shape.
    #[error("{path}: {what}")]
    Format {
        /// The file.
        path: String,
        /// What was wrong.
        what: String,
    },
}

/// Reads LineString / MultiLineString features from a GeoJSON file. A MultiLineString
/// becomes one [`EdgeLine`] per part. `side` is required; `category`, `method` and
/// `curb_height_m` are optional.
pub fn read_geojson(path: &std::path::Path) -> Result<(Vec<EdgeLine>, Option<Crs>), GeoJsonError> {
    let p = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| GeoJsonError::Io {
        path: p.clone(),
        source,
    })?;
    parse_geojson(&p, &text)
}

/// [`read_geojson`] on GeoJSON text held in memory; `name` stands for the file in messages.
pub fn parse_geojson(name: &str, text: &str) -> Result<(Vec<EdgeLine>, Option<Crs>), GeoJsonError> {
    let p = name.to_string();
    let fmt = |what: String| GeoJsonError::Format {
        path: p.clone(),
        what,
    };
    let v: serde_json::Value =
        serde_json::from_str(text).map_err(|e| fmt(format!("not JSON: {e}")))?;
    if v.get("type").and_then(|t| t.as_str()) != Some("FeatureCollection") {
        return Err(fmt("not a GeoJSON FeatureCollection".into()));
    }
    check_schema_version(&v).map_err(fmt)?;
    let crs = v
        .get("crs")
        .and_then(|c| c.get("properties"))
        .and_then(|p| p.get("name"))
        .and_then(|n| n.as_str())
        .map(|name| {
            name.rsplit("EPSG::")
                .next()
                .filter(|_| name.contains("EPSG::"))
                .and_then(|c| c.parse().ok())
                .map(Crs::Epsg)
                .unwrap_or_else(|| Crs::Wkt(name.to_string()))
        });
    let features = v
        .get("features")
        .and_then(|f| f.as_array())
        .ok_or_else(|| fmt("FeatureCollection without a features array".into()))?;
    let mut out = Vec::new();
    for (i, f) in features.iter().enumerate() {
        let props = f.get("properties").cloned().unwrap_or_default();
        let side = match props.get("side").and_then(|s| s.as_str()) {
            Some("left") => Side::Left,
            Some("right") => Side::Right,
            other => {
                return Err(fmt(format!(
                    "feature {i}: property side must be \"left\" or \"right\", found {other:?}"
                )))
            }
        };
        let category = match props.get("category").and_then(|s| s.as_str()) {
            None => None,
            Some(s) => Some(
                Category::parse(s)
                    .ok_or_else(|| fmt(format!("feature {i}: unknown category {s:?}")))?,
            ),
        };
        let method = props
            .get("method")
            .and_then(|s| s.as_str())
            .map(str::to_string);
        let curb_height_m = props.get("curb_height_m").and_then(|h| h.as_f64());
        let geom = f
            .get("geometry")
            .ok_or_else(|| fmt(format!("feature {i}: no geometry")))?;
        let parts: Vec<&serde_json::Value> = match geom.get("type").and_then(|t| t.as_str()) {
            Some("LineString") => vec![geom
                .get("coordinates")
                .ok_or_else(|| fmt(format!("feature {i}: no coordinates")))?],
            Some("MultiLineString") => geom
                .get("coordinates")
                .and_then(|c| c.as_array())
                .ok_or_else(|| fmt(format!("feature {i}: no coordinates")))?
                .iter()
                .collect(),
            other => {
                return Err(fmt(format!(
                    "feature {i}: geometry must be LineString or MultiLineString, found {other:?}"
                )))
            }
        };
        for part in parts {
            let coords = part
                .as_array()
                .ok_or_else(|| fmt(format!("feature {i}: coordinates are not an array")))?;
            let mut points = Vec::with_capacity(coords.len());
            for c in coords {
                let c = c
                    .as_array()
                    .ok_or_else(|| fmt(format!("feature {i}: a position is not an array")))?;
                let get = |k: usize| c.get(k).and_then(|x| x.as_f64());
                let (x, y) = match (get(0), get(1)) {
                    (Some(x), Some(y)) if x.is_finite() && y.is_finite() => (x, y),
                    _ => {
                        return Err(fmt(format!(
                            "feature {i}: a position is not two finite numbers"
                        )))
                    }
                };
                points.push([x, y, get(2).unwrap_or(0.0)]);
            }
            out.push(EdgeLine {
                points,
                side,
                category,
                method: method.clone(),
                curb_height_m,
            });
        }
    }
    Ok((out, crs))
}

/// The top-level member of a curbtrace GeoJSON file that holds its schema version, as the
/// string `"MAJOR.MINOR"` (`docs/output-formats.md`).
pub const SCHEMA_MEMBER: &str = "curbtrace_schema_version";

/// The schema version this build writes, `(major, minor)`. A minor step only adds optional
/// members or properties; a major step changes or removes one. Readers take any minor of
/// their major and refuse a newer major.
pub const SCHEMA_VERSION: (u32, u32) = (1, 0);

/// Checks the schema version of a parsed FeatureCollection: none (files from other tools,
/// reference files) or one of this build's major version passes; a newer major or a
/// malformed version is refused with a message saying why.
pub fn check_schema_version(fc: &serde_json::Value) -> Result<(), String> {
    let Some(v) = fc.get(SCHEMA_MEMBER) else {
        return Ok(());
    };
    let text = v.as_str().unwrap_or_default();
    let major = text
        .split_once('.')
        .and_then(|(ma, mi)| mi.parse::<u32>().ok().and(ma.parse::<u32>().ok()));
    match major {
        Some(m) if m <= SCHEMA_VERSION.0 => Ok(()),
        Some(_) => Err(format!(
            "{SCHEMA_MEMBER} {text} is newer than this curbtrace reads ({}.x): update curbtrace",
            SCHEMA_VERSION.0
        )),
        None => Err(format!(
            "{SCHEMA_MEMBER} must be a string \"MAJOR.MINOR\", found {v}"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::geojson::write_geojson;

    #[test]
    fn geojson_round_trip_keeps_properties_and_crs() {
        let lines = vec![EdgeLine {
            points: vec![[500000.0, 4000000.0, 10.0], [500003.0, 4000004.0, 10.5]],
            side: Side::Left,
            category: Some(Category::CurbCut),
            method: Some("bend".into()),
            curb_height_m: Some(0.15),
        }];
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.geojson");
        write_geojson(&path, &lines, Some(&Crs::Epsg(6677))).unwrap();
        let (back, crs) = read_geojson(&path).unwrap();
        assert_eq!(crs, Some(Crs::Epsg(6677)));
        assert_eq!(back, lines);
        assert!((back[0].length_m() - 5.0).abs() < 1e-9);
    }

    #[test]
    fn wkt_with_root_epsg_authority_is_the_same_crs_as_the_code() {
        let wkt = Crs::Wkt(r#"PROJCS["JGD2011 / UTM zone 54N",GEOGCS["JGD2011",AUTHORITY["EPSG","6668"]],UNIT["metre",1,AUTHORITY["EPSG","9001"]],AUTHORITY["EPSG","6691"]]"#.into());
        assert_eq!(wkt.epsg_code(), Some(6691));
        assert!(wkt.same_as(&Crs::Epsg(6691)));
        assert!(!wkt.same_as(&Crs::Epsg(6668)));
        let nested_only =
            Crs::Wkt(r#"PROJCS["x",GEOGCS["y",AUTHORITY["EPSG","6668"]],UNIT["metre",1]]"#.into());
        assert_eq!(nested_only.epsg_code(), None);
    }

    #[test]
    fn geojson_without_side_is_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.geojson");
        std::fs::write(
            &path,
            r#"{"type":"FeatureCollection","features":[{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0],[1,1]]}}]}"#,
        )
        .unwrap();
        let err = read_geojson(&path).unwrap_err().to_string();
        assert!(err.contains("bad.geojson") && err.contains("side"), "{err}");
    }
}
