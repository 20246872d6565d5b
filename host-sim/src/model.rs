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
    /// A bus bay or setback: the curb swings out from its line and back, not parallel to
    /// the trajectory on the tapers.
    BusBay,
    /// A flush edge: road meeting the verge or paving with no step, longer than a curb
    /// cut (extracted lines only; the reference has no such category).
    Flush,
}

impl Category {
    /// All categories, in table order.
    pub const ALL: [Category; 5] = [
        Category::Curb,
        Category::CurbCut,
        Category::Intersection,
        Category::BusBay,
        Category::Flush,
    ];

    /// The GeoJSON spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Category::Curb => "curb",
            Category::CurbCut => "curb_cut",
            Category::Intersection => "intersection",
            Category::BusBay => "bus_bay",
            Category::Flush => "flush",
        }
    }

    /// The categories a reference line can have (the simulator's and a surveyor's
    /// reference), in table order.
    pub const REFERENCE: [Category; 4] = [
        Category::Curb,
        Category::CurbCut,
        Category::Intersection,
        Category::BusBay,
    ];

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
    /// The surveyed curb beside the toe, per vertex (extracted lines from the bend method);
    /// `None` for reference lines and lines read from files without it.
    pub detail: Option<Box<CurbDetail>>,
}

/// The curb beside a toe line, one entry per vertex of the toe (docs/spec.md §2, "Curb
/// geometry").
#[derive(Clone, Debug, PartialEq, Default)]
pub struct CurbDetail {
    /// Top of curb (the arris) beside each toe vertex, `[x, y, z]` in the LAS CRS.
    pub top: Vec<[f64; 3]>,
    /// Curb height at each vertex, metres: top z − toe z.
    pub height_m: Vec<f64>,
    /// Whether each toe vertex rests on an observed candidate (true) or was placed by the
    /// tracker between observations (a virtual profile's toe, a bridged gap).
    pub measured: Vec<bool>,
    /// Whether the top at each vertex was measured on a profile (true) or interpolated
    /// from the measured ones beside it.
    pub top_measured: Vec<bool>,
    /// The class of the edge at each vertex (the stretches are cut where it changes).
    pub class: Vec<Category>,
    /// The stretch's kind of support: `true` when it was bridged (most of it placed by the
    /// tracker, no observed candidate for at least [`BRIDGED_MIN_M`]), set when an edge is
    /// cut into stretches.
    pub bridged: bool,
    /// Observed candidates (one per scanline crossing the toe) per metre of the stretch.
    pub support_per_m: f64,
    /// The scanner (channel key) whose tracker placed each vertex, where the edges of
    /// several scanners were fused (`stream::fuse`); empty otherwise.
    pub scanner: Vec<u16>,
    /// The pass (`stream::passes`) whose tracker placed each vertex, where edges of
    /// several scanners or passes were fused; empty otherwise.
    pub pass: Vec<u16>,
}

/// Shortest run of bridged toe vertices that makes a stretch of its own, metres; shorter
/// runs stay in the measured stretch around them.
pub const BRIDGED_MIN_M: f64 = 1.0;

impl CurbDetail {
    /// Per-vertex detail for `n` vertices with every vertex measured and no top known.
    pub fn measured(toe: &[[f64; 3]]) -> Self {
        Self {
            top: toe.to_vec(),
            height_m: vec![0.0; toe.len()],
            measured: vec![true; toe.len()],
            top_measured: vec![false; toe.len()],
            class: vec![Category::Curb; toe.len()],
            bridged: false,
            support_per_m: 0.0,
            scanner: Vec::new(),
            pass: Vec::new(),
        }
    }

    /// Vertices `a..b`.
    pub fn slice(&self, a: usize, b: usize) -> Self {
        Self {
            top: self.top[a..b].to_vec(),
            height_m: self.height_m[a..b].to_vec(),
            measured: self.measured[a..b].to_vec(),
            top_measured: self.top_measured[a..b].to_vec(),
            class: self.class[a..b].to_vec(),
            bridged: self.bridged,
            support_per_m: self.support_per_m,
            scanner: self
                .scanner
                .get(a..b)
                .map(<[u16]>::to_vec)
                .unwrap_or_default(),
            pass: self.pass.get(a..b).map(<[u16]>::to_vec).unwrap_or_default(),
        }
    }

    /// `self` followed by `other`.
    pub fn append(&mut self, other: &Self) {
        self.top.extend_from_slice(&other.top);
        self.height_m.extend_from_slice(&other.height_m);
        self.measured.extend_from_slice(&other.measured);
        self.top_measured.extend_from_slice(&other.top_measured);
        self.class.extend_from_slice(&other.class);
        // Per-vertex scanners and passes only where both sides have them.
        for (a, b) in [
            (&mut self.scanner, &other.scanner),
            (&mut self.pass, &other.pass),
        ] {
            if !a.is_empty() && !b.is_empty() {
                a.extend_from_slice(b);
            } else {
                a.clear();
            }
        }
    }

    /// The detail of the vertices in reverse order.
    pub fn reversed(&self) -> Self {
        let rev = |v: &[bool]| v.iter().rev().copied().collect::<Vec<_>>();
        Self {
            top: self.top.iter().rev().copied().collect(),
            height_m: self.height_m.iter().rev().copied().collect(),
            measured: rev(&self.measured),
            top_measured: rev(&self.top_measured),
            class: self.class.iter().rev().copied().collect(),
            bridged: self.bridged,
            support_per_m: self.support_per_m,
            scanner: self.scanner.iter().rev().copied().collect(),
            pass: self.pass.iter().rev().copied().collect(),
        }
    }

    /// The scanners that placed any vertex, ascending (empty where not fused).
    pub fn scanners(&self) -> Vec<u16> {
        let mut s = self.scanner.clone();
        s.sort_unstable();
        s.dedup();
        s
    }

    /// The passes that placed any vertex, ascending (empty where not fused).
    pub fn passes(&self) -> Vec<u16> {
        let mut s = self.pass.clone();
        s.sort_unstable();
        s.dedup();
        s
    }
}

impl EdgeLine {
    /// Vertices `a..b` with their detail, the other properties as they are.
    pub fn sub(&self, a: usize, b: usize) -> Self {
        Self {
            points: self.points[a..b].to_vec(),
            detail: self.detail.as_ref().map(|d| Box::new(d.slice(a, b))),
            ..self.clone()
        }
    }

    /// `self` continued by `other`'s vertices (and detail, where both have it); the other
    /// properties are `other`'s.
    pub fn joined(&self, other: &Self) -> Self {
        let mut points = self.points.clone();
        points.extend_from_slice(&other.points);
        let detail = match (&self.detail, &other.detail) {
            (Some(a), Some(b)) => {
                let mut d = a.clone();
                d.append(b);
                Some(d)
            }
            _ => None,
        };
        Self {
            points,
            detail,
            ..other.clone()
        }
    }

    /// The line seen from the other direction of travel: vertices in reverse order, the
    /// other side.
    pub fn reversed(&self) -> Self {
        Self {
            points: self.points.iter().rev().copied().collect(),
            detail: self.detail.as_ref().map(|d| Box::new(d.reversed())),
            side: match self.side {
                Side::Left => Side::Right,
                Side::Right => Side::Left,
            },
            ..self.clone()
        }
    }

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
/// `curb_height_m` are optional. Features with `line` = `top` (schema 2) are not lines of
/// their own: each becomes the [`CurbDetail`] top of the toe feature with the same `edge`,
/// whose `heights_m`, `bridged` and `support_per_m` fill the rest of the detail.
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
    // Schema 2: top-of-curb features, by the `edge` of their toe, and each toe's `edge`.
    let mut tops: std::collections::HashMap<u64, Vec<[f64; 3]>> = Default::default();
    let mut toe_edge: Vec<Option<u64>> = Vec::new();
    for (i, f) in features.iter().enumerate() {
        let props = f.get("properties").cloned().unwrap_or_default();
        let is_top = match props.get("line").and_then(|s| s.as_str()) {
            None | Some("toe") => false,
            Some("top") => true,
            Some(other) => {
                return Err(fmt(format!(
                    "feature {i}: property line must be \"toe\" or \"top\", found {other:?}"
                )))
            }
        };
        let edge = props.get("edge").and_then(|e| e.as_u64());
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
            if is_top {
                if let Some(k) = edge {
                    tops.insert(k, points);
                }
                continue;
            }
            let detail = props
                .get("heights_m")
                .and_then(|h| h.as_array())
                .filter(|h| h.len() == points.len())
                .map(|h| {
                    let bridged = props.get("bridged").and_then(|b| b.as_bool()) == Some(true);
                    let n = points.len();
                    Box::new(CurbDetail {
                        top: points.clone(),
                        height_m: h.iter().map(|v| v.as_f64().unwrap_or(0.0)).collect(),
                        measured: vec![!bridged; n],
                        top_measured: vec![true; n],
                        class: vec![category.unwrap_or(Category::Curb); n],
                        bridged,
                        support_per_m: props
                            .get("support_per_m")
                            .and_then(|s| s.as_f64())
                            .unwrap_or(0.0),
                        scanner: Vec::new(),
                        pass: Vec::new(),
                    })
                });
            toe_edge.push(edge);
            out.push(EdgeLine {
                points,
                side,
                category,
                method: method.clone(),
                curb_height_m,
                detail,
            });
        }
    }
    for (e, k) in out.iter_mut().zip(toe_edge) {
        let top = k.and_then(|k| tops.remove(&k));
        match (e.detail.as_mut(), top) {
            (Some(d), Some(top)) if top.len() == e.points.len() => d.top = top,
            (Some(_), _) => e.detail = None,
            _ => {}
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
pub const SCHEMA_VERSION: (u32, u32) = (2, 0);

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
            detail: None,
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
