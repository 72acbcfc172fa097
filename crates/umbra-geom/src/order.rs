//! The strict vertex order that makes multiplicity deterministic.
//!
//! Paper 001 (Milet, Kobrtek, Zemčík, "Fast and Robust Tessellation-Based Silhouette
//! Shadows"), Section 2.2, Eq. 1 and Algorithm 2: `Greater(A, B) = sgn(A - B) · (4, 2, 1)`,
//! i.e. a lexicographic order on (x, y, z).
//!
//! Each component comparison is written as two direct comparisons, never as the sign of a
//! subtraction: `a - b` can underflow to 0 (or overflow to ±inf) for distinct `a`, `b`,
//! which would make two distinct vertices compare equal and break the strictness the
//! reference-edge choice depends on. `-0.0` and `+0.0` compare equal, which is why
//! [`crate::weld`] welds them into one vertex.

use std::cmp::Ordering;

/// `sgn(a - b)` computed by comparison: exact for every pair of finite floats.
#[inline(always)]
fn sign_of_difference(a: f32, b: f32) -> i32 {
    (a > b) as i32 - (a < b) as i32
}

/// Alg. 2 of paper 001: positive when `a > b`, negative when `a < b`, zero when equal.
#[inline(always)]
pub fn greater(a: [f32; 3], b: [f32; 3]) -> i32 {
    4 * sign_of_difference(a[0], b[0]) + 2 * sign_of_difference(a[1], b[1]) + sign_of_difference(a[2], b[2])
}

/// `a < b` in the order of Eq. 1.
#[inline(always)]
pub fn less(a: [f32; 3], b: [f32; 3]) -> bool {
    greater(a, b) < 0
}

/// The same order as an [`Ordering`], for sorting.
#[inline]
pub fn compare(a: [f32; 3], b: [f32; 3]) -> Ordering {
    greater(a, b).cmp(&0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_is_lexicographic() {
        assert!(greater([1.0, 0.0, 0.0], [0.0, 9.0, 9.0]) > 0);
        assert!(greater([0.0, 1.0, 0.0], [0.0, 0.0, 9.0]) > 0);
        assert!(greater([0.0, 0.0, 1.0], [0.0, 0.0, 0.0]) > 0);
        assert!(greater([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]) < 0);
        assert_eq!(greater([1.0, 2.0, 3.0], [1.0, 2.0, 3.0]), 0);
    }

    /// Regression pin: the smallest subnormals differ, but `a - b` in a flush-to-zero
    /// world (or any GPU) would be zero. Direct comparison keeps them ordered.
    #[test]
    fn order_subnormal_neighbours() {
        let a = f32::from_bits(2);
        let b = f32::from_bits(1);
        assert!(greater([a, 0.0, 0.0], [b, 0.0, 0.0]) > 0);
        assert!(less([b, 0.0, 0.0], [a, 0.0, 0.0]));
    }

    /// `f32::MAX - (-f32::MAX)` overflows to +inf: still correct by comparison.
    #[test]
    fn order_extreme_values() {
        assert!(greater([f32::MAX, 0.0, 0.0], [-f32::MAX, 0.0, 0.0]) > 0);
        assert!(greater([-f32::MAX, 5.0, 0.0], [f32::MAX, -5.0, 0.0]) < 0);
    }

    #[test]
    fn order_signed_zero_is_equal() {
        assert_eq!(greater([0.0, -0.0, 0.0], [-0.0, 0.0, 0.0]), 0);
    }
}
