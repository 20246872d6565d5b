//! Candidates linked ring to ring into curb polylines, per side (docs/frames.md,
//! *Linking*).
//!
//! The accepted candidates of one side are taken in order of x (from behind the vehicle to
//! ahead of it). Each joins the open polyline whose prediction it fits best, or starts a
//! new one:
//!
//! - the prediction is the polyline's last vertex moved along the polyline's direction
//!   over the last up to 3 vertices (straight ahead, parallel to the vehicle, while it has
//!   one vertex);
//! - a candidate fits when it is 0 < Δx ≤ [`LinkParams::max_gap_m`] ahead of the last vertex
//!   and within [`LinkParams::tolerance_m`] + [`LinkParams::tolerance_per_m`] · Δx of the
//!   prediction laterally.
//!
//! Polylines with fewer than [`LinkParams::min_vertices`] vertices are dropped (a curb is
//! crossed by several rings; a lone candidate is not evidence).

use serde::{Deserialize, Serialize};

/// Parameters of the linking (`[link]` in a config file).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LinkParams {
    /// Largest step ahead between consecutive vertices, metres: an HDL-64E's rings lie up
    /// to about 2 m apart on the road at 20 m, and the vehicle hides up to 8 m around
    /// itself from the low rings.
    pub max_gap_m: f64,
    /// Lateral tolerance to the prediction, metres.
    pub tolerance_m: f64,
    /// Lateral tolerance added per metre ahead, metres (bends).
    pub tolerance_per_m: f64,
    /// Fewest vertices of a kept polyline.
    pub min_vertices: usize,
}

impl Default for LinkParams {
    fn default() -> Self {
        Self {
            max_gap_m: 8.0,
            tolerance_m: 0.25,
            tolerance_per_m: 0.05,
            min_vertices: 3,
        }
    }
}

/// Links points `[x, y]` (any order) into chains of indices into `pts`, each in order of
/// x; chains shorter than `min_vertices` are dropped.
pub fn link(pts: &[[f64; 2]], p: &LinkParams) -> Vec<Vec<usize>> {
    let mut order: Vec<usize> = (0..pts.len()).collect();
    order.sort_by(|&a, &b| pts[a][0].total_cmp(&pts[b][0]).then(a.cmp(&b)));
    let mut chains: Vec<Vec<usize>> = Vec::new();
    for &i in &order {
        let [x, y] = pts[i];
        let mut best: Option<(usize, f64)> = None;
        for (c, chain) in chains.iter().enumerate() {
            let last = pts[*chain.last().expect("chains are never empty")];
            let dx = x - last[0];
            if !(dx > 0.0 && dx <= p.max_gap_m) {
                continue;
            }
            let first = pts[chain[chain.len().saturating_sub(3)]];
            let slope = if last[0] - first[0] > 0.5 {
                (last[1] - first[1]) / (last[0] - first[0])
            } else {
                0.0
            };
            let miss = (y - (last[1] + slope * dx)).abs();
            if miss <= p.tolerance_m + p.tolerance_per_m * dx && best.is_none_or(|(_, m)| miss < m)
            {
                best = Some((c, miss));
            }
        }
        match best {
            Some((c, _)) => chains[c].push(i),
            None => chains.push(vec![i]),
        }
    }
    chains.retain(|c| c.len() >= p.min_vertices);
    chains
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_curb_becomes_one_chain_and_strays_are_dropped() {
        let mut pts: Vec<[f64; 2]> = (0..10)
            .map(|k| [-8.0 + 2.0 * k as f64, 5.9 + 0.01 * (k % 2) as f64])
            .collect();
        pts.push([3.0, 3.0]); // a stray candidate on the road
        pts.push([30.0, 5.9]); // beyond the gap
        let chains = link(&pts, &LinkParams::default());
        assert_eq!(chains, vec![(0..10).collect::<Vec<_>>()]);
    }

    #[test]
    fn two_parallel_curbs_stay_apart_and_a_bend_is_followed() {
        let mut pts = Vec::new();
        for k in 0..8 {
            let x = 4.0 + 1.5 * k as f64;
            pts.push([x, 4.0]);
            pts.push([x, 6.0 + 0.15 * (x - 4.0)]); // veers away at 8.5°
        }
        let chains = link(&pts, &LinkParams::default());
        assert_eq!(chains.len(), 2);
        assert!(chains.iter().all(|c| c.len() == 8));
        assert!(chains[0].iter().all(|&i| i % 2 == 0));
    }
}
