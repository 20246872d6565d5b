//! §3.2 Pre-processing: statistical outlier removal (Rusu et al. 2008) and voxel-grid
//! down-sampling to an even density.

use rayon::prelude::*;
use rstar::primitives::GeomWithData;
use rstar::RTree;
use std::collections::HashMap;

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
///
/// `cell_m` only sets the speed (the neighbours are exact for any value): it is the column
/// size of the search grid, best about two point spacings (after the voxel grid, two voxels).
pub fn statistical_outlier_removal(
    pts: &[[f64; 3]],
    k: usize,
    std_mul: f64,
    cell_m: f64,
) -> Vec<[f64; 3]> {
    if pts.len() <= k {
        return pts.to_vec();
    }
    let mean_d = mean_knn_distances(pts, k, cell_m);
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

/// Rings of grid columns searched before the exact R-tree fallback.
const KNN_MAX_RING: i64 = 6;

/// The mean distance of every point to its `k` nearest other points (exact; `pts.len() > k`).
///
/// Points are sorted into vertical columns of `cell_m` × `cell_m`, by z inside a column.
/// A query looks at the (2r+1)² columns around its own and the z range ±r·`cell_m`, for
/// r = 1, 2, …: every point within r·`cell_m` lies in that box, so once the k-th nearest
/// found is within r·`cell_m` it is the true k-th nearest. The rare point (an isolated
/// outlier) still short of k neighbours after [`KNN_MAX_RING`] rings asks an R-tree built
/// on first use. On voxelised MLS points this is 10–20× faster than an R-tree for all.
pub fn mean_knn_distances(pts: &[[f64; 3]], k: usize, cell_m: f64) -> Vec<f64> {
    let col = |p: &[f64; 3]| {
        (
            (p[0] / cell_m).floor() as i64,
            (p[1] / cell_m).floor() as i64,
        )
    };
    let mut order: Vec<u32> = (0..pts.len() as u32).collect();
    order.par_sort_unstable_by(|&a, &b| {
        let (pa, pb) = (&pts[a as usize], &pts[b as usize]);
        col(pa)
            .cmp(&col(pb))
            .then(pa[2].total_cmp(&pb[2]))
            .then(a.cmp(&b))
    });
    let sorted_z: Vec<f64> = order.iter().map(|&i| pts[i as usize][2]).collect();
    let mut columns: HashMap<(i64, i64), (usize, usize)> = HashMap::new();
    let mut a = 0;
    while a < order.len() {
        let c = col(&pts[order[a] as usize]);
        let mut b = a + 1;
        while b < order.len() && col(&pts[order[b] as usize]) == c {
            b += 1;
        }
        columns.insert(c, (a, b));
        a = b;
    }
    let tree: std::sync::OnceLock<RTree<GeomWithData<[f64; 3], usize>>> =
        std::sync::OnceLock::new();
    pts.par_iter()
        .enumerate()
        .map_init(Vec::new, |d2: &mut Vec<f64>, (i, p)| {
            let c = col(p);
            for r in 1..=KNN_MAX_RING {
                let reach = r as f64 * cell_m;
                d2.clear();
                for cx in c.0 - r..=c.0 + r {
                    for cy in c.1 - r..=c.1 + r {
                        let Some(&(a, b)) = columns.get(&(cx, cy)) else {
                            continue;
                        };
                        let zs = &sorted_z[a..b];
                        let lo = a + zs.partition_point(|&z| z < p[2] - reach);
                        let hi = a + zs.partition_point(|&z| z <= p[2] + reach);
                        for &j in &order[lo..hi] {
                            if j as usize != i {
                                let q = &pts[j as usize];
                                d2.push(
                                    (q[0] - p[0]).powi(2)
                                        + (q[1] - p[1]).powi(2)
                                        + (q[2] - p[2]).powi(2),
                                );
                            }
                        }
                    }
                }
                if d2.len() >= k {
                    d2.select_nth_unstable_by(k - 1, f64::total_cmp);
                    if d2[k - 1] <= reach * reach {
                        return d2[..k].iter().map(|d| d.sqrt()).sum::<f64>() / k as f64;
                    }
                }
            }
            let tree = tree.get_or_init(|| {
                RTree::bulk_load(
                    pts.iter()
                        .enumerate()
                        .map(|(i, p)| GeomWithData::new(*p, i))
                        .collect(),
                )
            });
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
        let kept = statistical_outlier_removal(&pts, 8, 2.0, 0.1);
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
        assert_eq!(statistical_outlier_removal(&pts, 8, 1.0, 0.1).len(), 2);
        assert!(voxel_downsample(&[], 0.1).is_empty());
    }

    #[test]
    fn grid_neighbours_equal_brute_force() {
        // Random points with clumps and far outliers: the grid search with any column size
        // gives the brute-force mean 5-NN distances (to rounding).
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut pts: Vec<[f64; 3]> = (0..600)
            .map(|_| {
                [
                    rng.gen_range(0.0..3.0),
                    rng.gen_range(0.0..1.0),
                    rng.gen_range(0.0..0.2),
                ]
            })
            .collect();
        pts.extend([[10.0, 10.0, 5.0], [-4.0, 0.5, 0.1], [1.0, 0.5, 3.0]]);
        let brute: Vec<f64> = pts
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let mut d: Vec<f64> = pts
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != i)
                    .map(|(_, q)| {
                        ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2))
                            .sqrt()
                    })
                    .collect();
                d.sort_by(f64::total_cmp);
                d[..5].iter().sum::<f64>() / 5.0
            })
            .collect();
        for cell in [0.02, 0.1, 0.5] {
            let got = mean_knn_distances(&pts, 5, cell);
            for (g, b) in got.iter().zip(&brute) {
                assert!((g - b).abs() < 1e-12, "cell {cell}: {g} vs {b}");
            }
        }
    }
}
