//! Points in any order are put in time order here, stably (equal times keep file order).
//!
//! Sorting holds a `u32` permutation and one temporary column (12 B per point) on top of
//! the columns.

use super::PointColumns;
use rayon::prelude::*;

impl PointColumns {
    /// Sorts by time, stably, if not sorted already. Returns true when it reordered.
    pub(super) fn sort_by_time(&mut self) -> bool {
        if self.t.windows(2).all(|w| w[0] <= w[1]) {
            return false;
        }
        // Stable sort of a u32 permutation (rayon's par_sort_by is stable); then each
        // column is gathered through it with one temporary column at a time.
        let t = &self.t;
        let mut perm: Vec<u32> = (0..t.len() as u32).collect();
        perm.par_sort_by(|&a, &b| t[a as usize].total_cmp(&t[b as usize]));
        fn gather<T: Copy + Send + Sync>(v: &mut Vec<T>, perm: &[u32]) {
            let out: Vec<T> = perm.par_iter().map(|&i| v[i as usize]).collect();
            *v = out;
        }
        gather(&mut self.x, &perm);
        gather(&mut self.y, &perm);
        gather(&mut self.z, &perm);
        gather(&mut self.t, &perm);
        gather(&mut self.intensity, &perm);
        gather(&mut self.scan_angle_deg, &perm);
        gather(&mut self.channel, &perm);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorts_stably_and_says_whether_it_reordered() {
        let mut c = PointColumns::default();
        for (k, t) in [2.0, 1.0, 2.0, 0.5].into_iter().enumerate() {
            c.push(k as f64, 0.0, 0.0, t, k as u16, 0.0, 0);
        }
        assert!(c.sort_by_time());
        assert_eq!(c.t, vec![0.5, 1.0, 2.0, 2.0]);
        assert_eq!(c.x, vec![3.0, 1.0, 0.0, 2.0]);
        assert_eq!(c.intensity, vec![3, 1, 0, 2]);
        assert!(!c.sort_by_time());
    }
}
