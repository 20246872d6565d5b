//! Edges as AutoCAD DXF (ASCII, R12): one 3D POLYLINE per line of a stretch (toe and top of
//! curb), in the LAS coordinates, on one layer per line kind and class (`TOE_CURB`,
//! `TOP_CURB`, `TOE_CURB_CUT`, …, `TOE_UNCLASSIFIED`); bridged stretches are drawn with the
//! line type `DASHED`; a fused stretch's polylines carry the scanners and passes that
//! contributed as extended data of the application `CURBTRACE` (`scanners=0;1`,
//! `passes=0;1`). DXF has no place for a CRS: the file opens with DXF comment groups
//! (code 999) naming the schema version and the CRS.

use super::features::{features, LineKind};
use super::format::{OutputError, OutputFormat};
use crate::model::{Category, Crs, EdgeLine, SCHEMA_MEMBER, SCHEMA_VERSION};
use dxf::entities::{Entity, EntityType, Polyline, Vertex};
use dxf::enums::AcadVersion;
use dxf::tables::{AppId, Layer, LineType};
use dxf::{Color, Drawing, Point};
use dxf::{XData, XDataItem};
use std::io::Write;
use std::path::Path;

/// The application name of the extended data naming a fused stretch's scanners and passes.
pub const XDATA_APP: &str = "CURBTRACE";

/// The line type of bridged stretches.
pub const BRIDGED_LINE_TYPE: &str = "DASHED";

/// The layer of a line: its kind and class, upper case.
pub fn layer_name(kind: LineKind, category: Option<Category>) -> String {
    let class = category.map_or("unclassified", Category::as_str);
    format!(
        "{}_{}",
        kind.as_str().to_ascii_uppercase(),
        class.to_ascii_uppercase()
    )
}

/// The AutoCAD colour index of a class's layer.
fn layer_color(category: Option<Category>) -> u8 {
    match category {
        Some(Category::Curb) => 7,
        Some(Category::CurbCut) => 3,
        Some(Category::Intersection) => 1,
        Some(Category::BusBay) => 5,
        Some(Category::Flush) => 4,
        None => 8,
    }
}

/// The comment lines at the head of the file.
fn header_comments(crs: Option<&Crs>) -> Vec<String> {
    let crs_line = match crs {
        Some(Crs::Epsg(code)) => format!("CRS EPSG:{code}"),
        Some(c @ Crs::Wkt(wkt)) => {
            let one_line = wkt.split_whitespace().collect::<Vec<_>>().join(" ");
            match c.epsg_code() {
                Some(code) => format!("CRS EPSG:{code} WKT {one_line}"),
                None => format!("CRS WKT {one_line}"),
            }
        }
        None => "CRS unknown (coordinates as in the LAS file)".to_string(),
    };
    vec![
        format!(
            "curbtrace road edges, {SCHEMA_MEMBER} {}.{}",
            SCHEMA_VERSION.0, SCHEMA_VERSION.1
        ),
        crs_line,
    ]
}

/// Writes `edges` as DXF at `path`, replacing any file there.
pub fn write_dxf(path: &Path, edges: &[EdgeLine], crs: Option<&Crs>) -> Result<(), OutputError> {
    let enc = |e: dxf::DxfError| OutputError::encode(path, OutputFormat::Dxf, e);
    let mut drawing = Drawing::new();
    // R12 needs no table handles; the crate writes the tables of R13 and later without the
    // handles those versions require, which CAD programs must then repair.
    drawing.header.version = AcadVersion::R12;
    // Dashes of 0.5 m, gaps of 0.25 m (drawing units: the LAS CRS's, metres).
    drawing.add_line_type(LineType {
        name: BRIDGED_LINE_TYPE.into(),
        description: "Bridged by the tracker __ __ __".into(),
        element_count: 2,
        total_pattern_length: 0.75,
        dash_dot_space_lengths: vec![0.5, -0.25],
        ..Default::default()
    });
    for kind in [LineKind::Toe, LineKind::Top] {
        for class in Category::ALL.into_iter().map(Some).chain([None]) {
            drawing.add_layer(Layer {
                name: layer_name(kind, class),
                color: Color::from_index(layer_color(class)),
                ..Default::default()
            });
        }
    }
    let mut app_id = false;
    for f in features(edges) {
        let mut poly = Polyline::default();
        poly.set_is_3d_polyline(true);
        for p in f.points {
            poly.add_vertex(&mut drawing, Vertex::new(Point::new(p[0], p[1], p[2])));
        }
        let mut entity = Entity::new(EntityType::Polyline(poly));
        entity.common.layer = layer_name(f.kind, f.stretch.category);
        if f.bridged() == Some(true) {
            entity.common.line_type_name = BRIDGED_LINE_TYPE.into();
        }
        let items: Vec<XDataItem> = [("scanners", f.scanners()), ("passes", f.passes())]
            .into_iter()
            .filter_map(|(k, v)| v.map(|v| XDataItem::Str(format!("{k}={v}"))))
            .collect();
        if !items.is_empty() {
            if !app_id {
                drawing.add_app_id(AppId {
                    name: XDATA_APP.into(),
                    ..Default::default()
                });
                app_id = true;
            }
            entity.common.x_data.push(XData {
                application_name: XDATA_APP.into(),
                items,
            });
        }
        drawing.add_entity(entity);
    }
    let mut body = Vec::new();
    drawing.save(&mut body).map_err(enc)?;
    let file = std::fs::File::create(path).map_err(|e| OutputError::io(path, e))?;
    let mut out = std::io::BufWriter::new(file);
    let io = |e| OutputError::io(path, e);
    for line in header_comments(crs) {
        write!(out, "999\r\n{line}\r\n").map_err(io)?;
    }
    out.write_all(&body).map_err(io)?;
    out.flush().map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_are_kind_and_class_in_upper_case() {
        assert_eq!(
            layer_name(LineKind::Toe, Some(Category::CurbCut)),
            "TOE_CURB_CUT"
        );
        assert_eq!(
            layer_name(LineKind::Top, Some(Category::BusBay)),
            "TOP_BUS_BAY"
        );
        assert_eq!(layer_name(LineKind::Toe, None), "TOE_UNCLASSIFIED");
    }

    #[test]
    fn the_crs_comment_is_one_line() {
        let c = header_comments(Some(&Crs::Wkt(
            "PROJCS[\"x\",\n  UNIT[\"metre\",1],\n  AUTHORITY[\"EPSG\",\"32633\"]]".into(),
        )));
        assert_eq!(
            c[1],
            "CRS EPSG:32633 WKT PROJCS[\"x\", UNIT[\"metre\",1], AUTHORITY[\"EPSG\",\"32633\"]]"
        );
        assert!(c.iter().all(|l| !l.contains('\n')));
    }
}
