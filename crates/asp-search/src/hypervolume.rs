//! Pareto dominance, Pareto fronts and the hypervolume indicator (thesis 6.4.2), for
//! maximisation: a point dominates another when it is at least as large in every objective and
//! larger in one; the hypervolume of a set is the volume of the region between the reference
//! point and the points.
//!
//! The 2-D hypervolume is an exact sweep (`O(n log n)`); more objectives use the exact
//! hypervolume-by-slicing-objectives recursion (HSO), which slices along the last objective and
//! sums slabs of (d-1)-dimensional hypervolumes down to the 2-D sweep.

/// Whether `a` dominates `b` (maximisation): `a >= b` everywhere and `a > b` somewhere.
pub fn dominates(a: &[f64], b: &[f64]) -> bool {
    let mut strictly = false;
    for (x, y) in a.iter().zip(b) {
        if x < y {
            return false;
        }
        if x > y {
            strictly = true;
        }
    }
    strictly
}

/// Whether `a >= b` in every objective (`a` dominates or equals `b`).
pub fn weakly_dominates(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).all(|(x, y)| x >= y)
}

/// Exact hypervolume of 2-D points relative to `reference` (points that do not exceed the
/// reference in both objectives add nothing).
pub fn hypervolume_2d(points: &[[f64; 2]], reference: [f64; 2]) -> f64 {
    hypervolume_2d_in_place(&mut points.to_vec(), reference)
}

/// [`hypervolume_2d`] on a buffer it may reorder (no allocation).
pub fn hypervolume_2d_in_place(points: &mut [[f64; 2]], reference: [f64; 2]) -> f64 {
    // x descending; for equal x, y descending (points that compare equal are identical)
    points.sort_unstable_by(|a, b| b[0].total_cmp(&a[0]).then(b[1].total_cmp(&a[1])));
    let mut area = 0.0;
    let mut top = reference[1];
    for p in points.iter() {
        if p[0] <= reference[0] {
            break; // so is every later point
        }
        if p[1] > top {
            area += (p[0] - reference[0]) * (p[1] - top);
            top = p[1];
        }
    }
    area
}

/// Exact hypervolume of `points` (each of length `reference.len()`) relative to `reference`.
pub fn hypervolume(points: &[&[f64]], reference: &[f64]) -> f64 {
    let d = reference.len();
    let pts: Vec<Vec<f64>> =
        points.iter().filter(|p| p.len() == d && p.iter().zip(reference).all(|(x, r)| x > r)).map(|p| p.to_vec()).collect();
    hso(pts, reference)
}

fn hso(mut pts: Vec<Vec<f64>>, reference: &[f64]) -> f64 {
    let d = reference.len();
    if pts.is_empty() || d == 0 {
        return 0.0;
    }
    match d {
        1 => pts.iter().map(|p| p[0] - reference[0]).fold(0.0, f64::max),
        2 => {
            let p2: Vec<[f64; 2]> = pts.iter().map(|p| [p[0], p[1]]).collect();
            hypervolume_2d(&p2, [reference[0], reference[1]])
        }
        _ => {
            // Slice along the last objective, from the largest value down.
            pts.sort_by(|a, b| b[d - 1].total_cmp(&a[d - 1]));
            let mut volume = 0.0;
            let mut slice: Vec<Vec<f64>> = Vec::with_capacity(pts.len());
            for k in 0..pts.len() {
                let projected = pts[k][..d - 1].to_vec();
                // keep the slice free of dominated points (cheap, and keeps recursion small)
                if !slice.iter().any(|q| weakly_dominates(q, &projected)) {
                    slice.retain(|q| !weakly_dominates(&projected, q));
                    slice.push(projected);
                }
                let lower = if k + 1 < pts.len() { pts[k + 1][d - 1] } else { reference[d - 1] };
                let height = pts[k][d - 1] - lower;
                if height > 0.0 {
                    volume += height * hso(slice.clone(), &reference[..d - 1]);
                }
            }
            volume
        }
    }
}

/// A set of mutually non-dominated points (maximisation) with a payload each, e.g. the
/// sequence that reached the point. Equal points are kept once (the first to arrive).
#[derive(Clone, Debug)]
pub struct ParetoFront<P> {
    dim: usize,
    points: Vec<f64>,
    payloads: Vec<P>,
}

impl<P> ParetoFront<P> {
    /// An empty front of `dim`-dimensional points.
    pub fn new(dim: usize) -> Self {
        ParetoFront { dim, points: Vec::new(), payloads: Vec::new() }
    }

    /// The number of objectives.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.payloads.len()
    }

    /// Whether the front is empty.
    pub fn is_empty(&self) -> bool {
        self.payloads.is_empty()
    }

    /// Point `k`.
    pub fn point(&self, k: usize) -> &[f64] {
        &self.points[k * self.dim..(k + 1) * self.dim]
    }

    /// The payload of point `k`.
    pub fn payload(&self, k: usize) -> &P {
        &self.payloads[k]
    }

    /// The points with their payloads.
    pub fn iter(&self) -> impl Iterator<Item = (&[f64], &P)> + '_ {
        self.points.chunks_exact(self.dim.max(1)).zip(&self.payloads)
    }

    /// Whether some point of the front dominates or equals `v`.
    pub fn covers(&self, v: &[f64]) -> bool {
        self.points.chunks_exact(self.dim.max(1)).any(|p| weakly_dominates(p, v))
    }

    /// Adds `v` unless a point dominates or equals it, removing the points `v` dominates.
    /// `payload` is only called when `v` is added. Returns whether it was added.
    pub fn insert(&mut self, v: &[f64], payload: impl FnOnce() -> P) -> bool {
        debug_assert_eq!(v.len(), self.dim);
        if self.covers(v) {
            return false;
        }
        let dim = self.dim;
        let mut k = 0;
        while k < self.payloads.len() {
            if dominates(v, &self.points[k * dim..(k + 1) * dim]) {
                self.payloads.swap_remove(k);
                let last = self.payloads.len();
                if k != last {
                    let (a, b) = self.points.split_at_mut(last * dim);
                    a[k * dim..(k + 1) * dim].copy_from_slice(&b[..dim]);
                }
                self.points.truncate(last * dim);
            } else {
                k += 1;
            }
        }
        self.points.extend_from_slice(v);
        self.payloads.push(payload());
        true
    }

    /// The exact hypervolume relative to `reference`.
    pub fn hypervolume(&self, reference: &[f64]) -> f64 {
        if self.dim == 2 {
            let pts: Vec<[f64; 2]> = self.points.chunks_exact(2).map(|p| [p[0], p[1]]).collect();
            return hypervolume_2d(&pts, [reference[0], reference[1]]);
        }
        let pts: Vec<&[f64]> = self.points.chunks_exact(self.dim.max(1)).collect();
        hypervolume(&pts, reference)
    }

    /// The points sorted lexicographically (objective 0 descending, then 1, ...), with payloads.
    pub fn sorted(&self) -> Vec<(Vec<f64>, &P)> {
        let mut v: Vec<(Vec<f64>, &P)> = self.iter().map(|(p, q)| (p.to_vec(), q)).collect();
        v.sort_by(|a, b| {
            for (x, y) in a.0.iter().zip(&b.0) {
                match y.total_cmp(x) {
                    std::cmp::Ordering::Equal => continue,
                    o => return o,
                }
            }
            std::cmp::Ordering::Equal
        });
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dominance() {
        assert!(dominates(&[2.0, 1.0], &[1.0, 1.0]));
        assert!(!dominates(&[1.0, 1.0], &[1.0, 1.0]));
        assert!(weakly_dominates(&[1.0, 1.0], &[1.0, 1.0]));
        assert!(!dominates(&[2.0, 0.0], &[1.0, 1.0]));
    }

    #[test]
    fn two_d_by_hand() {
        // staircase (3,1), (2,2), (1,3) from (0,0): 3 + 2 + 1 = 6
        let pts = [[3.0, 1.0], [2.0, 2.0], [1.0, 3.0]];
        assert_eq!(hypervolume_2d(&pts, [0.0, 0.0]), 6.0);
        // a dominated point and a point below the reference change nothing
        let more = [[3.0, 1.0], [2.0, 2.0], [1.0, 3.0], [1.0, 1.0], [5.0, -1.0]];
        assert_eq!(hypervolume_2d(&more, [0.0, 0.0]), 6.0);
        // another reference point: (3-1)*(1-0.5) + (2-1)*(2-1) + 0 = 2
        assert_eq!(hypervolume_2d(&pts, [1.0, 0.5]), 2.0);
        assert_eq!(hypervolume_2d(&[], [0.0, 0.0]), 0.0);
    }

    #[test]
    fn front_insertion() {
        let mut f = ParetoFront::new(2);
        assert!(f.insert(&[1.0, 1.0], || "a"));
        assert!(!f.insert(&[1.0, 1.0], || "dup"));
        assert!(!f.insert(&[0.5, 1.0], || "dominated"));
        assert!(f.insert(&[2.0, 0.0], || "b"));
        assert!(f.insert(&[2.0, 2.0], || "c"));
        assert_eq!(f.len(), 1);
        assert_eq!(*f.payload(0), "c");
        assert_eq!(f.hypervolume(&[0.0, 0.0]), 4.0);
    }

    #[test]
    fn general_d_matches_2d() {
        let pts = [[3.0, 1.0], [2.0, 2.5], [1.0, 3.0], [0.5, 0.5]];
        let refs: Vec<&[f64]> = pts.iter().map(|p| p.as_slice()).collect();
        let a = hypervolume(&refs, &[0.0, 0.0]);
        let b = hypervolume_2d(&pts, [0.0, 0.0]);
        assert!((a - b).abs() < 1e-12);
        // a cube of side 2 in 3-D
        assert_eq!(hypervolume(&[&[2.0, 2.0, 2.0]], &[0.0, 0.0, 0.0]), 8.0);
    }
}
