//! Edges as CSV vertex lists (`curbtrace extract --format csv`).

use crate::model::EdgeLine;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Writes edges as CSV vertex lists: `edge,side,vertex,x,y,z` (one row per vertex).
pub fn write_edges(path: &Path, edges: &[EdgeLine]) -> std::io::Result<()> {
    let mut w = BufWriter::new(std::fs::File::create(path)?);
    writeln!(w, "edge,side,vertex,x,y,z")?;
    for (k, e) in edges.iter().enumerate() {
        for (v, p) in e.points.iter().enumerate() {
            writeln!(
                w,
                "{k},{},{v},{:.4},{:.4},{:.4}",
                e.side.as_str(),
                p[0],
                p[1],
                p[2]
            )?;
        }
    }
    w.flush()
}
