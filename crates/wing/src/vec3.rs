//! Vectors of ℝ³ as `[f64; 3]`, components in whatever frame the caller names: the sums,
//! products and norms that the rigid-body loads ([`crate::virtual_wing`]) and the vortex
//! lattice ([`crate::lattice`]) share. Rotations (`Mat3`) are in [`crate::kinematics`].

/// a + b.
#[inline]
pub(crate) fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a − b.
#[inline]
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// (a + b) / 2.
#[inline]
pub(crate) fn midpoint(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        0.5 * (a[0] + b[0]),
        0.5 * (a[1] + b[1]),
        0.5 * (a[2] + b[2]),
    ]
}

/// a · b.
#[inline]
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// |a|.
#[inline]
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// a × b.
#[inline]
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_products_of_the_unit_vectors() {
        let [x, y, z] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(cross(x, y), z);
        assert_eq!(cross(y, z), x);
        assert_eq!(cross(z, x), y);
        assert_eq!(cross(y, x), [0.0, 0.0, -1.0]);
        assert_eq!(dot(x, y), 0.0);
        let a = [3.0, -4.0, 12.0];
        assert_eq!(norm(a), 13.0);
        assert_eq!(dot(cross(a, [1.0, 2.0, 3.0]), a), 0.0);
        assert_eq!(sub(add(a, x), x), a);
        assert_eq!(midpoint(a, [1.0, 0.0, -2.0]), [2.0, -2.0, 5.0]);
    }
}
