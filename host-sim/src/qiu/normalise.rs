//! §3.3.1 Eliminating the influence of rough road: "divide the point clouds into small
//! grid, calculate the minimum value along z-axis for each grid, each point in grid minus
//! the minimum z value" — a DSM − DTM with the DTM taken as the lowest point per cell.

use std::collections::HashMap;

/// Per point: the minimum z of its cell (the local terrain) and its height above it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Normalised {
    /// Lowest z in the point's grid cell, metres.
    pub ground_z: Vec<f64>,
    /// z − `ground_z`, metres (≥ 0).
    pub z_norm: Vec<f64>,
}

/// Normalises heights on a square grid of `cell_m` (§3.3.1).
pub fn normalise_to_grid_min(pts: &[[f64; 3]], cell_m: f64) -> Normalised {
    let key = |p: &[f64; 3]| {
        (
            (p[0] / cell_m).floor() as i64,
            (p[1] / cell_m).floor() as i64,
        )
    };
    let mut min_z: HashMap<(i64, i64), f64> = HashMap::new();
    for p in pts {
        let e = min_z.entry(key(p)).or_insert(f64::INFINITY);
        if p[2] < *e {
            *e = p[2];
        }
    }
    // Lookups only: the result does not depend on the map's iteration order.
    let ground_z: Vec<f64> = pts.iter().map(|p| min_z[&key(p)]).collect();
    let z_norm = pts.iter().zip(&ground_z).map(|(p, g)| p[2] - g).collect();
    Normalised { ground_z, z_norm }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sloped_plane_becomes_a_saw_tooth_below_one_cell_of_rise() {
        // z = 0.1·x (10 % slope) sampled every 0.1 m over x ∈ [0, 2), y = 0.25; 0.5 m cells.
        // Cell 0 holds x = 0.0 … 0.4: minimum 0.0, so x = 0.4 has z_norm 0.04; cell 1 starts
        // at x = 0.5 (z = 0.05) and x = 0.7 gives 0.07 − 0.05 = 0.02.
        let pts: Vec<[f64; 3]> = (0..20)
            .map(|i| {
                let x = i as f64 * 0.1;
                [x, 0.25, 0.1 * x]
            })
            .collect();
        let n = normalise_to_grid_min(&pts, 0.5);
        assert!((n.z_norm[4] - 0.04).abs() < 1e-12);
        assert!((n.z_norm[7] - 0.02).abs() < 1e-12);
        assert!((n.ground_z[7] - 0.05).abs() < 1e-12);
        // Every point ends up less than one cell's rise (0.05 m) above its cell minimum,
        // where the raw heights span 0.19 m.
        assert!(n.z_norm.iter().all(|&z| (0.0..0.05 - 1e-9).contains(&z)));
        // The first point of every cell is its minimum.
        for i in [0, 5, 10, 15] {
            assert_eq!(n.z_norm[i], 0.0);
        }
    }

    #[test]
    fn a_curb_keeps_its_step_in_the_cell_that_holds_the_toe() {
        // Road at z = 0 for x < 0.3, sidewalk at 0.15 m beyond, all in one 0.5 m cell; a
        // second cell entirely on the sidewalk normalises to 0.
        let pts = [[0.1, 0.1, 0.0], [0.4, 0.1, 0.15], [0.7, 0.1, 0.15]];
        let n = normalise_to_grid_min(&pts, 0.5);
        assert_eq!(n.z_norm, vec![0.0, 0.15, 0.0]);
    }
}
