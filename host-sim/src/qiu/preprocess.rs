//! §3.2 Pre-processing: statistical outlier removal (Rusu et al. 2008) and voxel-grid
//! down-sampling to an even density.

use rayon::prelude::*;
use rstar::primitives::GeomWithData;
use rstar::RTree;

/// Voxel-grid down-sampling: one point per occupied voxel of edge `voxel_m`, the centroid
/// of the points in it (as PCL's `VoxelGrid`). The output is ordered by voxel index, so it
/// does not depend on the input order.
pub fn voxel_downsample(pts: &[[f64; 3]], voxel_m: f64) -> Vec<[f64; 3]> {
    let key = |p: &[f64; 3]| {
        [
            (p[0] / voxel_m).floor() as i64,
            (p[1] / voxel_m).floor() as i64,
            (p[2] / voxel_m).floor() as i64,
        ]
    };
    let mut keyed: Vec<([i64; 3], usize)> = pts
        .par_iter()
        .enumerate()
        .filter(|(_, p)| p.iter().all(|v| v.is_finite()))
        .map(|(i, p)| (key(p), i))
        .collect();
    keyed.par_sort_unstable();
    let mut out = Vec::new();
    let mut i = 0;
    while i < keyed.len() {
        let k = keyed[i].0;
        let mut sum = [0.0; 3];
        let mut n = 0.0;
        while i < keyed.len() && keyed[i].0 == k {
            let p = &pts[keyed[i].1];
            sum[0] += p[0];
            sum[1] += p[1];
            sum[2] += p[2];
            n += 1.0;
            i += 1;
        }
        out.push([sum[0] / n, sum[1] / n, sum[2] / n]);
    }
    out
}

/// Statistical outlier removal (Rusu et al. 2008, §3.2): the mean distance of every point
/// to its `k` nearest neighbours; points whose mean exceeds μ + `std_mul`·σ of all means
/// are removed. Returns the kept points in input order. With `k` or fewer points nothing
/// can be judged and everything is kept.
pub fn statistical_outlier_removal(pts: &[[f64; 3]], k: usize, std_mul: f64) -> Vec<[f64; 3]> {
    if pts.len() <= k {
        return pts.to_vec();
    }
    let tree = RTree::bulk_load(
        pts.iter()
            .enumerate()
            .map(|(i, p)| GeomWithData::new(*p, i))
            .collect(),
    );
    let mean_d: Vec<f64> = pts
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let mut sum = 0.0;
            let mut n = 0;
            for q in tree.nearest_neighbor_iter(p) {
                if q.data == i {
                    continue;
                }
                let g = q.geom();
                sum +=
                    ((g[0] - p[0]).powi(2) + (g[1] - p[1]).powi(2) + (g[2] - p[2]).powi(2)).sqrt();
                n += 1;
                if n == k {
                    break;
                }
            }
            sum / n as f64
        })
        .collect();
    let n = mean_d.len() as f64;
    let mu = mean_d.iter().sum::<f64>() / n;
    let var = mean_d.iter().map(|d| (d - mu).powi(2)).sum::<f64>() / n;
    let limit = mu + std_mul * var.sqrt();
    pts.iter()
        .zip(&mean_d)
        .filter(|(_, &d)| d <= limit)
        .map(|(p, _)| *p)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1 m × 1 m plane at z = 0 sampled on a 0.05 m grid (21 × 21 = 441 points).
    fn plane() -> Vec<[f64; 3]> {
        let mut v = Vec::new();
        for i in 0..=20 {
            for j in 0..=20 {
                v.push([i as f64 * 0.05, j as f64 * 0.05, 0.0]);
            }
        }
        v
    }

    #[test]
    fn sor_removes_an_isolated_outlier_and_keeps_the_plane() {
        let mut pts = plane();
        pts.push([0.5, 0.5, 1.0]); // 1 m above the middle: mean 8-NN distance ≈ 1 m
        let kept = statistical_outlier_removal(&pts, 8, 2.0);
        assert!(!kept.contains(&[0.5, 0.5, 1.0]));
        // Interior points have mean 8-NN distance (4·0.05 + 4·0.0707)/8 ≈ 0.060 m, corners
        // ≈ 0.092 m; the outlier (≈ 1 m) makes σ ≈ 0.045 m, so μ + 2σ ≈ 0.15 m keeps them all.
        assert_eq!(kept.len(), 441);
    }

    #[test]
    fn voxel_grid_keeps_one_centroid_per_occupied_voxel() {
        // 441 points on a 0.05 m grid over [0, 1]²; 0.1 m voxels: floor(x/0.1) takes
        // values 0..=10 (x = 1.0 alone in voxel 10) → 11 × 11 = 121 voxels.
        let pts = plane();
        let v = voxel_downsample(&pts, 0.1);
        assert_eq!(v.len(), 121);
        // Voxel (0, 0) holds x, y ∈ {0, 0.05} (floor(0.05/0.1) = 0): centroid (0.025, 0.025).
        assert!((v[0][0] - 0.025).abs() < 1e-12 && (v[0][1] - 0.025).abs() < 1e-12);
        // Two identical points collapse to one; a NaN point is dropped.
        let v = voxel_downsample(
            &[[1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [f64::NAN, 0.0, 0.0]],
            0.1,
        );
        assert_eq!(v, vec![[1.0, 1.0, 1.0]]);
    }

    #[test]
    fn tiny_inputs_are_kept() {
        let pts = vec![[0.0; 3], [1.0; 3]];
        assert_eq!(statistical_outlier_removal(&pts, 8, 1.0).len(), 2);
        assert!(voxel_downsample(&[], 0.1).is_empty());
    }
}
