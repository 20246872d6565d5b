//! Edges as an OGC GeoPackage (1.2): an SQLite file with the three mandatory tables
//! (`gpkg_spatial_ref_sys`, `gpkg_contents`, `gpkg_geometry_columns`) and one feature table
//! `edges` of LineString Z geometries in the LAS CRS.
//!
//! Geometries are GeoPackage binary blobs: the `GP` header with the srs id and the XY
//! envelope, then ISO WKB LineString Z, encoded by geozero's GeoPackage WKB dialect.

use super::features::features;
use super::format::{OutputError, OutputFormat};
use crate::model::{Crs, EdgeLine, SCHEMA_MEMBER, SCHEMA_VERSION};
use geozero::wkb::{WkbDialect, WkbWriter};
use geozero::{CoordDimensions, GeomProcessor};
use rusqlite::{params, Connection};
use std::path::Path;

/// `PRAGMA application_id` of a GeoPackage: ASCII "GPKG".
const APPLICATION_ID: i32 = 0x4750_4B47;
/// `PRAGMA user_version`: GeoPackage 1.2.0. The file uses nothing newer, and older readers
/// (GDAL 3.6) warn about a newer version number.
const USER_VERSION: i32 = 10200;
/// The name of the feature table.
pub const TABLE: &str = "edges";
/// srs_id of a CRS given as WKT without an EPSG code (GDAL's range for user systems).
const CUSTOM_SRS_ID: i32 = 100_000;

/// The WGS 84 row every GeoPackage holds (GeoPackage requirement 11).
const WGS84_WKT: &str = r#"GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563,AUTHORITY["EPSG","7030"]],AUTHORITY["EPSG","6326"]],PRIMEM["Greenwich",0,AUTHORITY["EPSG","8901"]],UNIT["degree",0.0174532925199433,AUTHORITY["EPSG","9122"]],AXIS["Latitude",NORTH],AXIS["Longitude",EAST],AUTHORITY["EPSG","4326"]]"#;

/// The schema of a GeoPackage's mandatory tables (GeoPackage annex C).
const CORE_TABLES: &str = "
CREATE TABLE gpkg_spatial_ref_sys (
  srs_name TEXT NOT NULL,
  srs_id INTEGER PRIMARY KEY,
  organization TEXT NOT NULL,
  organization_coordsys_id INTEGER NOT NULL,
  definition TEXT NOT NULL,
  description TEXT
);
CREATE TABLE gpkg_contents (
  table_name TEXT NOT NULL PRIMARY KEY,
  data_type TEXT NOT NULL,
  identifier TEXT UNIQUE,
  description TEXT DEFAULT '',
  last_change DATETIME NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ','now')),
  min_x DOUBLE,
  min_y DOUBLE,
  max_x DOUBLE,
  max_y DOUBLE,
  srs_id INTEGER,
  CONSTRAINT fk_gc_r_srs_id FOREIGN KEY (srs_id) REFERENCES gpkg_spatial_ref_sys(srs_id)
);
CREATE TABLE gpkg_geometry_columns (
  table_name TEXT NOT NULL,
  column_name TEXT NOT NULL,
  geometry_type_name TEXT NOT NULL,
  srs_id INTEGER NOT NULL,
  z TINYINT NOT NULL,
  m TINYINT NOT NULL,
  CONSTRAINT pk_geom_cols PRIMARY KEY (table_name, column_name),
  CONSTRAINT uk_gc_table_name UNIQUE (table_name),
  CONSTRAINT fk_gc_tn FOREIGN KEY (table_name) REFERENCES gpkg_contents(table_name),
  CONSTRAINT fk_gc_srs FOREIGN KEY (srs_id) REFERENCES gpkg_spatial_ref_sys (srs_id)
);
CREATE TABLE edges (
  fid INTEGER PRIMARY KEY AUTOINCREMENT NOT NULL,
  geom LINESTRING,
  side TEXT NOT NULL,
  method TEXT,
  length_m DOUBLE,
  curb_height_m DOUBLE,
  category TEXT,
  line TEXT NOT NULL,
  edge INTEGER NOT NULL,
  bridged BOOLEAN,
  support_per_m DOUBLE,
  scanners TEXT,
  passes TEXT
);
";

/// One row of `gpkg_spatial_ref_sys`.
struct SrsRow {
    name: String,
    id: i32,
    organization: String,
    code: i32,
    definition: String,
}

/// The row for the LAS CRS: an EPSG code keeps its number as srs_id, with the WKT as the
/// definition when there is one ("undefined" otherwise: readers resolve the code); a WKT
/// without an EPSG code becomes an organisation-less definition (`NONE`).
fn srs_row(crs: &Crs) -> SrsRow {
    let wkt = match crs {
        Crs::Wkt(w) => Some(w.as_str()),
        Crs::Epsg(_) => None,
    };
    match crs.epsg_code().and_then(|c| i32::try_from(c).ok()) {
        Some(code) => SrsRow {
            name: wkt
                .and_then(wkt_name)
                .unwrap_or_else(|| format!("EPSG:{code}")),
            id: code,
            organization: "EPSG".into(),
            code,
            definition: wkt.unwrap_or("undefined").to_string(),
        },
        None => SrsRow {
            name: wkt.and_then(wkt_name).unwrap_or_else(|| "LAS CRS".into()),
            id: CUSTOM_SRS_ID,
            organization: "NONE".into(),
            code: CUSTOM_SRS_ID,
            definition: wkt.unwrap_or("undefined").to_string(),
        },
    }
}

/// The name of a WKT's root object: its first quoted string.
fn wkt_name(wkt: &str) -> Option<String> {
    let start = wkt.find('"')? + 1;
    let len = wkt[start..].find('"')?;
    Some(wkt[start..start + len].to_string()).filter(|n| !n.is_empty())
}

/// The GeoPackage geometry blob of a line: header with srs id and XY envelope, ISO WKB
/// LineString Z.
fn geometry_blob(points: &[[f64; 3]], srs_id: i32) -> geozero::error::Result<Vec<u8>> {
    let (min, max) = envelope(points.iter());
    let mut blob = Vec::with_capacity(48 + 9 + 24 * points.len());
    let mut w = WkbWriter::with_opts(
        &mut blob,
        WkbDialect::Geopackage,
        CoordDimensions::xyz(),
        Some(srs_id),
        vec![min[0], max[0], min[1], max[1]],
    );
    w.linestring_begin(true, points.len(), 0)?;
    for (i, p) in points.iter().enumerate() {
        w.coordinate(p[0], p[1], Some(p[2]), None, None, None, i)?;
    }
    w.linestring_end(true, 0)?;
    Ok(blob)
}

/// XY bounds `(min, max)` of the vertices; `(+inf, -inf)` when there are none.
pub(crate) fn envelope<'a>(points: impl Iterator<Item = &'a [f64; 3]>) -> ([f64; 2], [f64; 2]) {
    let mut min = [f64::INFINITY; 2];
    let mut max = [f64::NEG_INFINITY; 2];
    for p in points {
        for k in 0..2 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    }
    (min, max)
}

/// Writes `edges` as a GeoPackage at `path`, replacing any file there.
pub fn write_gpkg(path: &Path, edges: &[EdgeLine], crs: Option<&Crs>) -> Result<(), OutputError> {
    let sql = |e: rusqlite::Error| OutputError::encode(path, OutputFormat::GeoPackage, e);
    match std::fs::remove_file(path) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(OutputError::io(path, e)),
    }
    let mut db = Connection::open(path).map_err(sql)?;
    db.pragma_update(None, "application_id", APPLICATION_ID)
        .map_err(sql)?;
    db.pragma_update(None, "user_version", USER_VERSION)
        .map_err(sql)?;
    let tx = db.transaction().map_err(sql)?;
    tx.execute_batch(CORE_TABLES).map_err(sql)?;
    let mut rows = vec![
        SrsRow {
            name: "Undefined Cartesian SRS".into(),
            id: -1,
            organization: "NONE".into(),
            code: -1,
            definition: "undefined".into(),
        },
        SrsRow {
            name: "Undefined geographic SRS".into(),
            id: 0,
            organization: "NONE".into(),
            code: 0,
            definition: "undefined".into(),
        },
        SrsRow {
            name: "WGS 84 geodetic".into(),
            id: 4326,
            organization: "EPSG".into(),
            code: 4326,
            definition: WGS84_WKT.into(),
        },
    ];
    // Without a CRS the coordinates are still projected metres: the undefined Cartesian SRS.
    let srs_id = match crs.map(srs_row) {
        Some(row) => {
            let id = row.id;
            rows.retain(|r| r.id != id);
            rows.push(row);
            id
        }
        None => -1,
    };
    for r in &rows {
        tx.execute(
            "INSERT INTO gpkg_spatial_ref_sys \
             (srs_name, srs_id, organization, organization_coordsys_id, definition) \
             VALUES (?1, ?2, ?3, ?4, ?5)",
            params![r.name, r.id, r.organization, r.code, r.definition],
        )
        .map_err(sql)?;
    }
    let feats = features(edges);
    let (min, max) = envelope(feats.iter().flat_map(|f| f.points));
    let bounds = |v: f64| v.is_finite().then_some(v);
    tx.execute(
        "INSERT INTO gpkg_contents \
         (table_name, data_type, identifier, description, min_x, min_y, max_x, max_y, srs_id) \
         VALUES (?1, 'features', ?1, ?2, ?3, ?4, ?5, ?6, ?7)",
        params![
            TABLE,
            format!(
                "curbtrace road edges, {SCHEMA_MEMBER} {}.{}",
                SCHEMA_VERSION.0, SCHEMA_VERSION.1
            ),
            bounds(min[0]),
            bounds(min[1]),
            bounds(max[0]),
            bounds(max[1]),
            srs_id
        ],
    )
    .map_err(sql)?;
    tx.execute(
        "INSERT INTO gpkg_geometry_columns \
         (table_name, column_name, geometry_type_name, srs_id, z, m) \
         VALUES (?1, 'geom', 'LINESTRING', ?2, 1, 0)",
        params![TABLE, srs_id],
    )
    .map_err(sql)?;
    {
        let mut insert = tx
            .prepare(
                "INSERT INTO edges (geom, side, method, length_m, curb_height_m, category, \
                 line, edge, bridged, support_per_m, scanners, passes) \
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12)",
            )
            .map_err(sql)?;
        for f in &feats {
            let e = f.stretch;
            let blob = geometry_blob(f.points, srs_id)
                .map_err(|err| OutputError::encode(path, OutputFormat::GeoPackage, err))?;
            insert
                .execute(params![
                    blob,
                    e.side.as_str(),
                    e.method,
                    f.length_m(),
                    e.curb_height_m,
                    e.category.map(|c| c.as_str()),
                    f.kind.as_str(),
                    f.edge as i64,
                    f.bridged(),
                    f.support_per_m(),
                    f.scanners(),
                    f.passes(),
                ])
                .map_err(sql)?;
        }
    }
    tx.commit().map_err(sql)?;
    db.close().map_err(|(_, e)| sql(e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_geometry_blob_is_a_gpkg_header_and_iso_wkb_linestring_z() {
        let b = geometry_blob(&[[1.0, 2.0, 3.0], [4.0, -5.0, 6.0]], 6677).unwrap();
        assert_eq!(&b[..3], b"GP\0");
        // Flags: little endian, XY envelope (envelope code 1).
        assert_eq!(b[3], 0b0000_0011);
        assert_eq!(i32::from_le_bytes(b[4..8].try_into().unwrap()), 6677);
        let f = |k: usize| f64::from_le_bytes(b[k..k + 8].try_into().unwrap());
        assert_eq!([f(8), f(16), f(24), f(32)], [1.0, 4.0, -5.0, 2.0]);
        // WKB: little endian, type 1002 (LineString Z), two points.
        assert_eq!(b[40], 1);
        assert_eq!(u32::from_le_bytes(b[41..45].try_into().unwrap()), 1002);
        assert_eq!(u32::from_le_bytes(b[45..49].try_into().unwrap()), 2);
        assert_eq!([f(49), f(57), f(65)], [1.0, 2.0, 3.0]);
        assert_eq!([f(73), f(81), f(89)], [4.0, -5.0, 6.0]);
        assert_eq!(b.len(), 97);
    }

    #[test]
    fn a_wkt_without_code_is_an_organisation_less_definition() {
        let row = srs_row(&Crs::Wkt(r#"LOCAL_CS["site grid",UNIT["metre",1]]"#.into()));
        assert_eq!(row.organization, "NONE");
        assert_eq!(row.id, CUSTOM_SRS_ID);
        assert_eq!(row.name, "site grid");
        let row = srs_row(&Crs::Epsg(6677));
        assert_eq!((row.id, row.organization.as_str()), (6677, "EPSG"));
        assert_eq!(row.definition, "undefined");
    }
}
