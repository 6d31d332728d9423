//! Riemannian metrics: symmetric positive-definite 3x3 tensors `M = Q diag(h_i^-2) Q^T`, under
//! which an edge `e` has length `sqrt(e^T M e)` (1 = the wanted size along `e`).

use glam::{DMat3, DVec3};

/// Symmetric positive-definite 3x3 metric tensor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metric(pub DMat3);

impl Metric {
    /// The metric of size `h` in every direction.
    pub fn isotropic(h: f64) -> Self {
        Metric(DMat3::from_diagonal(DVec3::splat(h.powi(-2))))
    }

    /// Size `sizes[i]` along `directions[i]`; the directions must be orthonormal.
    pub fn from_sizes(directions: [DVec3; 3], sizes: [f64; 3]) -> Self {
        let q = DMat3::from_cols(directions[0], directions[1], directions[2]);
        Metric(q * DMat3::from_diagonal(DVec3::from_array(sizes.map(|h| h.powi(-2)))) * q.transpose())
    }

    pub fn matrix(&self) -> DMat3 {
        self.0
    }

    /// Length of edge vector `e` measured in the metric: `sqrt(e^T M e)`.
    pub fn edge_length(&self, e: DVec3) -> f64 {
        e.dot(self.0 * e).max(0.0).sqrt()
    }

    /// The wanted size along direction `d` (any length).
    pub fn size_along(&self, d: DVec3) -> f64 {
        d.length() / self.edge_length(d)
    }

    /// Principal sizes (ascending: the most restrictive first) and their orthonormal directions.
    pub fn principal_sizes(&self) -> ([f64; 3], [DVec3; 3]) {
        let (values, vectors) = symmetric_eigen(self.0);
        let mut order = [0, 1, 2];
        order.sort_by(|&a, &b| values[b].total_cmp(&values[a]));
        (order.map(|i| values[i].max(f64::MIN_POSITIVE).powf(-0.5)), order.map(|i| vectors.col(i)))
    }

    /// `Q f(Lambda) Q^T`: a function applied to the eigenvalues.
    fn map_eigenvalues(&self, f: impl Fn(f64) -> f64) -> DMat3 {
        let (values, q) = symmetric_eigen(self.0);
        q * DMat3::from_diagonal(DVec3::from_array(values.map(f))) * q.transpose()
    }

    /// The classical metric intersection (simultaneous reduction): in the basis where both are
    /// diagonal, keep the larger eigenvalue (the smaller size) of each direction. The result
    /// asks for at most the size of either input along every direction.
    pub fn intersect(&self, other: &Metric) -> Metric {
        let root = self.map_eigenvalues(f64::sqrt);
        let inverse_root = self.map_eigenvalues(|l| 1.0 / l.sqrt());
        // `other` seen in the frame where `self` is the identity.
        let relative = Metric(symmetrize(inverse_root * other.0 * inverse_root));
        let kept = relative.map_eigenvalues(|l| l.max(1.0));
        Metric(symmetrize(root * kept * root))
    }

    /// Interpolation at `t` in [0, 1] from `self` to `other` that varies sizes linearly:
    /// `((1 - t) M_a^-1/2 + t M_b^-1/2)^-2`.
    pub fn interpolate(&self, other: &Metric, t: f64) -> Metric {
        let size = |m: &Metric| m.map_eigenvalues(|l| 1.0 / l.sqrt());
        let mixed = Metric(symmetrize((1.0 - t) * size(self) + t * size(other)));
        Metric(mixed.map_eigenvalues(|h| h.powi(-2)))
    }
}

fn symmetrize(m: DMat3) -> DMat3 {
    (m + m.transpose()) * 0.5
}

/// Eigenvalues and orthonormal eigenvectors (the columns) of a symmetric 3x3 matrix, by cyclic
/// Jacobi rotations (unconditionally convergent, accurate to round-off for small eigenvalues).
pub fn symmetric_eigen(m: DMat3) -> ([f64; 3], DMat3) {
    // Column-major storage is row-major for a symmetric matrix.
    let mut a = m.to_cols_array_2d();
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..32 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        let diagonal = a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2);
        if off <= 1e-32 * diagonal || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            rotate(&mut a, &mut v, p, q);
        }
    }
    let vectors = DMat3::from_cols_array_2d(&[0, 1, 2].map(|j| [v[0][j], v[1][j], v[2][j]]));
    ([a[0][0], a[1][1], a[2][2]], vectors)
}

/// One Jacobi rotation zeroing `a[p][q]`: `a <- J^T a J`, `v <- v J`.
fn rotate(a: &mut [[f64; 3]; 3], v: &mut [[f64; 3]; 3], p: usize, q: usize) {
    if a[p][q] == 0.0 {
        return;
    }
    let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
    let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
    let c = 1.0 / (t * t + 1.0).sqrt();
    let s = t * c;
    let turn_columns = |m: &mut [[f64; 3]; 3]| {
        for row in m.iter_mut() {
            let (mp, mq) = (row[p], row[q]);
            row[p] = c * mp - s * mq;
            row[q] = s * mp + c * mq;
        }
    };
    turn_columns(a);
    turn_columns(v);
    let (row_p, row_q) = (a[p], a[q]);
    a[p] = [0, 1, 2].map(|k| c * row_p[k] - s * row_q[k]);
    a[q] = [0, 1, 2].map(|k| s * row_p[k] + c * row_q[k]);
    a[p][q] = 0.0;
    a[q][p] = 0.0;
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A random metric: sizes in [1e-3, 10] along a random rotation.
    fn metric() -> impl Strategy<Value = Metric> {
        (proptest::array::uniform3(-3.0f64..1.0), proptest::array::uniform3(-3.2f64..3.2)).prop_map(
            |(s, r)| {
                let q = glam::DQuat::from_euler(glam::EulerRot::XYZ, r[0], r[1], r[2]);
                let dirs = [q * DVec3::X, q * DVec3::Y, q * DVec3::Z];
                Metric::from_sizes(dirs, s.map(|e| 10f64.powf(e)))
            },
        )
    }

    fn close(a: &Metric, b: &Metric, tol: f64) -> bool {
        let scale =
            a.0.to_cols_array().iter().chain(&b.0.to_cols_array()).fold(0.0f64, |m, x| m.max(x.abs()));
        (a.0 - b.0).to_cols_array().iter().all(|d| d.abs() <= tol * scale)
    }

    #[test]
    fn sizes_are_recovered_along_their_directions() {
        let n = DVec3::new(1.0, 2.0, 2.0) / 3.0;
        let (t1, t2) = n.any_orthonormal_pair();
        let m = Metric::from_sizes([n, t1, t2], [0.01, 0.5, 2.0]);
        assert!((m.size_along(n) - 0.01).abs() < 1e-14);
        assert!((m.edge_length(t2 * 4.0) - 2.0).abs() < 1e-12);
        let (sizes, dirs) = m.principal_sizes();
        assert!(
            (sizes[0] - 0.01).abs() < 1e-12 && (sizes[1] - 0.5).abs() < 1e-9 && (sizes[2] - 2.0).abs() < 1e-9
        );
        assert!(dirs[0].dot(n).abs() > 1.0 - 1e-12);
    }

    #[test]
    fn intersection_of_crossed_anisotropies_takes_the_small_size_of_each() {
        let a = Metric::from_sizes([DVec3::X, DVec3::Y, DVec3::Z], [0.1, 1.0, 1.0]);
        let b = Metric::from_sizes([DVec3::X, DVec3::Y, DVec3::Z], [1.0, 0.2, 1.0]);
        let m = a.intersect(&b);
        assert!(close(&m, &Metric::from_sizes([DVec3::X, DVec3::Y, DVec3::Z], [0.1, 0.2, 1.0]), 1e-12));
    }

    #[test]
    fn interpolation_varies_sizes_linearly() {
        let a = Metric::isotropic(1.0);
        let b = Metric::from_sizes([DVec3::X, DVec3::Y, DVec3::Z], [3.0, 1.0, 0.5]);
        let m = a.interpolate(&b, 0.25);
        assert!((m.size_along(DVec3::X) - 1.5).abs() < 1e-12);
        assert!((m.size_along(DVec3::Z) - 0.875).abs() < 1e-12);
        assert!(close(&a.interpolate(&b, 1.0), &b, 1e-12));
    }

    proptest! {
        #[test]
        fn eigen_decomposition_reconstructs(m in metric()) {
            let (values, q) = symmetric_eigen(m.0);
            let back = q * DMat3::from_diagonal(DVec3::from_array(values)) * q.transpose();
            prop_assert!(close(&Metric(back), &m, 1e-12));
            prop_assert!(close(&Metric(q.transpose() * q), &Metric(DMat3::IDENTITY), 1e-12));
        }

        #[test]
        fn intersection_is_commutative_idempotent_and_restrictive(a in metric(), b in metric(),
                                                                   e in proptest::array::uniform3(-1.0f64..1.0)) {
            let (ab, ba) = (a.intersect(&b), b.intersect(&a));
            // Sizes span four decades, so metric entries span eight: the simultaneous reduction
            // is exact to about 1e-16 times that condition number.
            prop_assert!(close(&ab, &ba, 1e-7), "{:?} vs {:?}", ab, ba);
            prop_assert!(close(&a.intersect(&a), &a, 1e-9));
            let e = DVec3::from_array(e);
            let longest = a.edge_length(e).max(b.edge_length(e));
            // Never a larger size (a shorter metric length) than either input in any direction.
            prop_assert!(ab.edge_length(e) >= longest * (1.0 - 1e-9));
        }
    }
}
