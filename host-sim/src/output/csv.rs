//! Edges as CSV vertex lists (`curbtrace extract --format csv`).

use crate::model::EdgeLine;
use std::io::{BufWriter, Write};
use std::path::Path;

/// The header row: the toe vertex (`edge,side,vertex,x,y,z`, as in schema 1), then the
/// stretch's class and support and, where the curb was surveyed, the top of curb beside the
/// vertex and the curb height there (empty otherwise), then where several scanners or
/// passes were fused the scanner and the pass that placed the vertex (empty otherwise).
pub const HEADER: &str =
    "edge,side,vertex,x,y,z,category,bridged,support_per_m,top_x,top_y,top_z,height_m,scanner,pass";

/// Writes edges as CSV vertex lists, one row per toe vertex (see [`HEADER`]).
pub fn write_edges(path: &Path, edges: &[EdgeLine]) -> std::io::Result<()> {
    let mut w = BufWriter::new(std::fs::File::create(path)?);
    writeln!(w, "{HEADER}")?;
    for (k, e) in edges.iter().enumerate() {
        let cat = e.category.map_or("", |c| c.as_str());
        for (v, p) in e.points.iter().enumerate() {
            write!(
                w,
                "{k},{},{v},{:.4},{:.4},{:.4},{cat},",
                e.side.as_str(),
                p[0],
                p[1],
                p[2]
            )?;
            match e.detail.as_deref() {
                Some(d) if v < d.top.len() && v < d.height_m.len() => {
                    let t = d.top[v];
                    let id = |ids: &[u16]| ids.get(v).map(u16::to_string).unwrap_or_default();
                    writeln!(
                        w,
                        "{},{:.2},{:.4},{:.4},{:.4},{:.4},{},{}",
                        d.bridged,
                        d.support_per_m,
                        t[0],
                        t[1],
                        t[2],
                        d.height_m[v],
                        id(&d.scanner),
                        id(&d.pass)
                    )?;
                }
                _ => writeln!(w, ",,,,,,,")?,
            }
        }
    }
    w.flush()
}
