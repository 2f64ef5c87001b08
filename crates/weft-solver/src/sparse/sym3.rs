//! `Sym3`: a symmetric 3×3 block stored as its six distinct entries.

use glam::DVec3;

/// A symmetric 3×3 matrix: `[xx, yy, zz, xy, xz, yz]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Sym3(pub [f64; 6]);

impl Sym3 {
    /// s I.
    #[inline]
    pub fn scaled_identity(s: f64) -> Self {
        Self([s, s, s, 0.0, 0.0, 0.0])
    }

    /// s u uᵀ.
    #[inline]
    pub fn outer(u: DVec3, s: f64) -> Self {
        let v = u * s;
        Self([
            v.x * u.x,
            v.y * u.y,
            v.z * u.z,
            v.x * u.y,
            v.x * u.z,
            v.y * u.z,
        ])
    }

    /// s M.
    #[inline]
    pub fn scale(self, s: f64) -> Self {
        Self(self.0.map(|e| e * s))
    }

    /// The entrywise sum.
    #[inline]
    pub fn add(self, o: Self) -> Self {
        let (a, b) = (self.0, o.0);
        Self(std::array::from_fn(|k| a[k] + b[k]))
    }

    /// M u.
    #[inline]
    pub fn mul(&self, u: DVec3) -> DVec3 {
        let [xx, yy, zz, xy, xz, yz] = self.0;
        DVec3::new(
            xx * u.x + xy * u.y + xz * u.z,
            xy * u.x + yy * u.y + yz * u.z,
            xz * u.x + yz * u.y + zz * u.z,
        )
    }

    /// The inverse by cofactors, or zero when the determinant is not positive (the block of a
    /// symmetric positive definite matrix always has one).
    #[inline]
    pub fn inverse(&self) -> Self {
        let [xx, yy, zz, xy, xz, yz] = self.0;
        let cxx = yy * zz - yz * yz;
        let cxy = xz * yz - xy * zz;
        let cxz = xy * yz - xz * yy;
        let det = xx * cxx + xy * cxy + xz * cxz;
        if det.is_nan() || det <= 0.0 {
            return Self::default();
        }
        let inv = 1.0 / det;
        Self([
            cxx * inv,
            (xx * zz - xz * xz) * inv,
            (xx * yy - xy * xy) * inv,
            cxy * inv,
            cxz * inv,
            (xy * xz - xx * yz) * inv,
        ])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_times_block_is_identity() {
        let a = Sym3::scaled_identity(2.0)
            .add(Sym3::outer(DVec3::new(0.3, -1.0, 0.5), 4.0))
            .add(Sym3::outer(DVec3::new(0.0, 0.6, 0.8), 0.7).scale(-0.5));
        let inv = a.inverse();
        for u in [DVec3::X, DVec3::Y, DVec3::Z] {
            let back = inv.mul(a.mul(u));
            assert!((back - u).length() < 1e-14, "{back} != {u}");
        }
        assert_eq!(
            Sym3::default().inverse(),
            Sym3::default(),
            "singular → zero"
        );
    }
}
