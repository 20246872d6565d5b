//! Edges as AutoCAD DXF (ASCII, R12): one 3D POLYLINE per edge, in the LAS coordinates,
//! on one layer per line kind and class (`TOE_CURB`, `TOE_CURB_CUT`, `TOE_INTERSECTION`,
//! `TOE_BUS_BAY`, `TOE_UNCLASSIFIED`). DXF has no place for a CRS: the file opens with DXF
//! comment groups (code 999) naming the schema version and the CRS.

use super::format::{OutputError, OutputFormat};
use crate::model::{Category, Crs, EdgeLine, SCHEMA_MEMBER, SCHEMA_VERSION};
use dxf::entities::{Entity, EntityType, Polyline, Vertex};
use dxf::enums::AcadVersion;
use dxf::tables::Layer;
use dxf::{Color, Drawing, Point};
use std::io::Write;
use std::path::Path;

/// The line kind of every layer name: the toe of the curb (the top follows later).
const TOE: &str = "TOE";

/// The layer of an edge: its kind and class, upper case.
pub fn layer_name(category: Option<Category>) -> String {
    let class = category.map_or("unclassified", Category::as_str);
    format!("{TOE}_{}", class.to_ascii_uppercase())
}

/// The AutoCAD colour index of a class's layer.
fn layer_color(category: Option<Category>) -> u8 {
    match category {
        Some(Category::Curb) => 7,
        Some(Category::CurbCut) => 3,
        Some(Category::Intersection) => 1,
        Some(Category::BusBay) => 5,
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
    let classes = Category::ALL.into_iter().map(Some).chain([None]);
    for class in classes {
        drawing.add_layer(Layer {
            name: layer_name(class),
            color: Color::from_index(layer_color(class)),
            ..Default::default()
        });
    }
    for e in edges {
        let mut poly = Polyline::default();
        poly.set_is_3d_polyline(true);
        for p in &e.points {
            poly.add_vertex(&mut drawing, Vertex::new(Point::new(p[0], p[1], p[2])));
        }
        let mut entity = Entity::new(EntityType::Polyline(poly));
        entity.common.layer = layer_name(e.category);
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
        assert_eq!(layer_name(Some(Category::CurbCut)), "TOE_CURB_CUT");
        assert_eq!(layer_name(Some(Category::BusBay)), "TOE_BUS_BAY");
        assert_eq!(layer_name(None), "TOE_UNCLASSIFIED");
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
