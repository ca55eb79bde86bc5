//! Vertex-stage math in `f32`: vectors, 4x4 matrices and the float shim.
//!
//! Design note: everything before snapping runs in IEEE `f32`, in a fixed
//! order of operations, with no fused multiply-add (Rust never contracts
//! `a * b + c` on its own), so the host and a Cortex-M build compute the same
//! bits. Transcendental functions (`sin`, `cos`, `tan`, `sqrt`) go
//! through the [`FloatFns`] backends at the top of this file, chosen by cargo
//! feature: `libm` (default, correctly rounded or close to it) or `micromath`
//! (fast approximations). Nothing here decides coverage: the only float that
//! reaches the rasterizer is rounded to a named fixed-point format in
//! [`crate::fixed`] first.

#[cfg(not(any(feature = "libm", feature = "micromath")))]
compile_error!("microraster needs a float backend: enable feature `libm` (default) or `micromath`");

/// The float functions the vertex stage needs, from one backend.
///
/// `Libm` and `Micromath` implement it, each behind its cargo feature;
/// `DefaultFloat` is the one the plain constructors ([`Mat4::perspective`]
/// and friends) use: `libm` when that feature is on, else `micromath`. Both
/// may be enabled at once, and the `*_with` constructors pick one
/// explicitly (the host's speed-vs-error report compares them in one run).
pub trait FloatFns {
    /// Sine.
    fn sin(x: f32) -> f32;
    /// Cosine.
    fn cos(x: f32) -> f32;
    /// Tangent.
    fn tan(x: f32) -> f32;
    /// Square root.
    fn sqrt(x: f32) -> f32;
}

/// Accurate float functions from the `libm` crate.
#[cfg(feature = "libm")]
#[derive(Clone, Copy, Debug, Default)]
pub struct Libm;

#[cfg(feature = "libm")]
impl FloatFns for Libm {
    #[inline]
    fn sin(x: f32) -> f32 {
        libm::sinf(x)
    }
    #[inline]
    fn cos(x: f32) -> f32 {
        libm::cosf(x)
    }
    #[inline]
    fn tan(x: f32) -> f32 {
        libm::tanf(x)
    }
    #[inline]
    fn sqrt(x: f32) -> f32 {
        libm::sqrtf(x)
    }
}

/// Fast approximate float functions from the `micromath` crate.
#[cfg(feature = "micromath")]
#[derive(Clone, Copy, Debug, Default)]
pub struct Micromath;

#[cfg(feature = "micromath")]
impl FloatFns for Micromath {
    #[inline]
    fn sin(x: f32) -> f32 {
        micromath::F32Ext::sin(x)
    }
    #[inline]
    fn cos(x: f32) -> f32 {
        micromath::F32Ext::cos(x)
    }
    #[inline]
    fn tan(x: f32) -> f32 {
        micromath::F32Ext::tan(x)
    }
    /// micromath's bit-trick estimate (up to 6 % off) refined by two Newton
    /// steps (about `1e-6` relative): `look_at` normalises with it.
    #[inline]
    fn sqrt(x: f32) -> f32 {
        // 0 and infinity are their own roots (a Newton step on infinity
        // would compute inf / inf = NaN); NaN and negatives stay NaN.
        if x == 0.0 || x == f32::INFINITY {
            return x;
        }
        if x.is_nan() || x < 0.0 {
            return f32::NAN;
        }
        let mut y = micromath::F32Ext::sqrt(x);
        if y > 0.0 && y.is_finite() {
            y = 0.5 * (y + x / y);
            y = 0.5 * (y + x / y);
        }
        y
    }
}

/// The backend chosen by cargo feature (`libm` wins if both are on).
#[cfg(feature = "libm")]
pub type DefaultFloat = Libm;
/// The backend chosen by cargo feature (`libm` wins if both are on).
#[cfg(all(feature = "micromath", not(feature = "libm")))]
pub type DefaultFloat = Micromath;

/// The float shim used inside the crate.
pub(crate) mod fx {
    use super::{DefaultFloat, FloatFns};
    #[inline]
    pub fn sqrt(x: f32) -> f32 {
        DefaultFloat::sqrt(x)
    }

    /// `a.min(b)` (a NaN argument gives the other one), compared inline:
    /// Armv7E-M has no `vminnm`, and `f32::min` there is a call to
    /// `fminf` (about 20 instructions; a normal mask's build made 5,000
    /// of them). Only the sign of a zero result may differ.
    #[inline(always)]
    pub fn min(a: f32, b: f32) -> f32 {
        if a.is_nan() || b < a {
            b
        } else {
            a
        }
    }

    /// `a.max(b)`, compared inline (see [`min`]).
    #[inline(always)]
    pub fn max(a: f32, b: f32) -> f32 {
        if a.is_nan() || b > a {
            b
        } else {
            a
        }
    }
}

use core::ops::{Add, Mul, Neg, Sub};

/// A 3-component `f32` vector (object or world space).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vec3 {
    /// x component.
    pub x: f32,
    /// y component.
    pub y: f32,
    /// z component.
    pub z: f32,
}

impl Vec3 {
    /// The zero vector.
    pub const ZERO: Vec3 = Vec3::new(0.0, 0.0, 0.0);

    /// Builds a vector.
    pub const fn new(x: f32, y: f32, z: f32) -> Self {
        Vec3 { x, y, z }
    }

    /// Builds a vector from an array.
    pub const fn from_array(a: [f32; 3]) -> Self {
        Vec3::new(a[0], a[1], a[2])
    }

    /// Dot product.
    pub fn dot(self, o: Vec3) -> f32 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Cross product.
    pub fn cross(self, o: Vec3) -> Vec3 {
        Vec3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }

    /// Euclidean length.
    pub fn length(self) -> f32 {
        fx::sqrt(self.dot(self))
    }

    /// This vector scaled to unit length; the zero vector stays zero.
    pub fn normalize(self) -> Vec3 {
        self.normalize_with::<DefaultFloat>()
    }

    /// [`Vec3::normalize`] with the float backend `F`.
    pub fn normalize_with<F: FloatFns>(self) -> Vec3 {
        let len = F::sqrt(self.dot(self));
        if len > 0.0 {
            self * (1.0 / len)
        } else {
            Vec3::ZERO
        }
    }

    /// Extends to a point (`w = 1`).
    pub const fn extend(self, w: f32) -> Vec4 {
        Vec4::new(self.x, self.y, self.z, w)
    }

    /// True if every component is finite.
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    fn add(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl Sub for Vec3 {
    type Output = Vec3;
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl Neg for Vec3 {
    type Output = Vec3;
    fn neg(self) -> Vec3 {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}

impl Mul<f32> for Vec3 {
    type Output = Vec3;
    fn mul(self, s: f32) -> Vec3 {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}

/// A homogeneous `f32` vector: a clip-space position `(x, y, z, w)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vec4 {
    /// x component.
    pub x: f32,
    /// y component.
    pub y: f32,
    /// z component.
    pub z: f32,
    /// w component.
    pub w: f32,
}

impl Vec4 {
    /// Builds a vector.
    pub const fn new(x: f32, y: f32, z: f32, w: f32) -> Self {
        Vec4 { x, y, z, w }
    }

    /// Builds a vector from an array.
    pub const fn from_array(a: [f32; 4]) -> Self {
        Vec4::new(a[0], a[1], a[2], a[3])
    }

    /// True if every component is finite (no NaN, no infinity).
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite() && self.w.is_finite()
    }

    /// `self + (o - self) * t`, component-wise, in a fixed order.
    pub fn lerp(self, o: Vec4, t: f32) -> Vec4 {
        Vec4::new(
            self.x + (o.x - self.x) * t,
            self.y + (o.y - self.y) * t,
            self.z + (o.z - self.z) * t,
            self.w + (o.w - self.w) * t,
        )
    }
}

/// A column-major 4x4 `f32` matrix acting on column vectors (`M * v`), as in
/// OpenGL and glam. `cols[c][r]` is row `r` of column `c`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mat4 {
    /// The four columns.
    pub cols: [[f32; 4]; 4],
}

impl Default for Mat4 {
    fn default() -> Self {
        Mat4::IDENTITY
    }
}

impl Mat4 {
    /// The identity matrix.
    pub const IDENTITY: Mat4 = Mat4 {
        cols: [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    };

    /// Builds a matrix from rows, as it is written on paper.
    pub const fn from_rows(r: [[f32; 4]; 4]) -> Mat4 {
        Mat4 {
            cols: [
                [r[0][0], r[1][0], r[2][0], r[3][0]],
                [r[0][1], r[1][1], r[2][1], r[3][1]],
                [r[0][2], r[1][2], r[2][2], r[3][2]],
                [r[0][3], r[1][3], r[2][3], r[3][3]],
            ],
        }
    }

    /// Row `r` as an array, `None` for `r > 3`.
    pub const fn row(&self, r: usize) -> Option<[f32; 4]> {
        if r > 3 {
            return None;
        }
        Some([
            self.cols[0][r],
            self.cols[1][r],
            self.cols[2][r],
            self.cols[3][r],
        ])
    }

    /// The four rows, as the matrix is written on paper (the inverse of
    /// [`Mat4::from_rows`]).
    pub const fn rows(&self) -> [[f32; 4]; 4] {
        let c = &self.cols;
        [
            [c[0][0], c[1][0], c[2][0], c[3][0]],
            [c[0][1], c[1][1], c[2][1], c[3][1]],
            [c[0][2], c[1][2], c[2][2], c[3][2]],
            [c[0][3], c[1][3], c[2][3], c[3][3]],
        ]
    }

    /// A translation by `t`.
    pub const fn translation(t: Vec3) -> Mat4 {
        Mat4::from_rows([
            [1.0, 0.0, 0.0, t.x],
            [0.0, 1.0, 0.0, t.y],
            [0.0, 0.0, 1.0, t.z],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }

    /// A non-uniform scale.
    pub const fn scale(s: Vec3) -> Mat4 {
        Mat4::from_rows([
            [s.x, 0.0, 0.0, 0.0],
            [0.0, s.y, 0.0, 0.0],
            [0.0, 0.0, s.z, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }

    /// A right-handed rotation by `radians` about the x axis.
    pub fn rotation_x(radians: f32) -> Mat4 {
        Mat4::rotation_x_with::<DefaultFloat>(radians)
    }

    /// [`Mat4::rotation_x`] with the float backend `F`.
    pub fn rotation_x_with<F: FloatFns>(radians: f32) -> Mat4 {
        let (s, c) = (F::sin(radians), F::cos(radians));
        Mat4::from_rows([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, c, -s, 0.0],
            [0.0, s, c, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }

    /// A right-handed rotation by `radians` about the y axis.
    pub fn rotation_y(radians: f32) -> Mat4 {
        Mat4::rotation_y_with::<DefaultFloat>(radians)
    }

    /// [`Mat4::rotation_y`] with the float backend `F`.
    pub fn rotation_y_with<F: FloatFns>(radians: f32) -> Mat4 {
        let (s, c) = (F::sin(radians), F::cos(radians));
        Mat4::from_rows([
            [c, 0.0, s, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [-s, 0.0, c, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }

    /// A right-handed rotation by `radians` about the z axis.
    pub fn rotation_z(radians: f32) -> Mat4 {
        Mat4::rotation_z_with::<DefaultFloat>(radians)
    }

    /// [`Mat4::rotation_z`] with the float backend `F`.
    pub fn rotation_z_with<F: FloatFns>(radians: f32) -> Mat4 {
        let (s, c) = (F::sin(radians), F::cos(radians));
        Mat4::from_rows([
            [c, -s, 0.0, 0.0],
            [s, c, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }

    /// An OpenGL perspective projection (right-handed eye space looking down
    /// -z, clip z in `[-w, w]`), like `gluPerspective`.
    pub fn perspective(fov_y_radians: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
        Mat4::perspective_with::<DefaultFloat>(fov_y_radians, aspect, near, far)
    }

    /// [`Mat4::perspective`] with the float backend `F`.
    pub fn perspective_with<F: FloatFns>(
        fov_y_radians: f32,
        aspect: f32,
        near: f32,
        far: f32,
    ) -> Mat4 {
        let f = 1.0 / F::tan(fov_y_radians * 0.5);
        let nf = 1.0 / (near - far);
        Mat4::from_rows([
            [f / aspect, 0.0, 0.0, 0.0],
            [0.0, f, 0.0, 0.0],
            [0.0, 0.0, (far + near) * nf, 2.0 * far * near * nf],
            [0.0, 0.0, -1.0, 0.0],
        ])
    }

    /// A perspective projection whose window depth is `near / w`: 1/w
    /// depth, reversed (1 at the near plane, towards 0 far away) and with
    /// no far plane. Clip `z = 2 near - w` (eye space looking down -z, `w =
    /// -z_eye`), so the clip volume's `z <= w` is `w >= near` and `z >= -w`
    /// always holds; window depth `(z/w + 1) / 2 = near / w` is affine on
    /// the screen, so both rasterization modes interpolate it exactly as
    /// they interpolate window z. Draw with
    /// [`DepthFunc::Greater`](crate::DepthFunc::Greater) (or
    /// `GreaterEqual`) into buffers cleared to 0. In `u16` and `u32`
    /// buffers it has the precision of window z for the same near plane
    /// (both are affine in `1/w`: `d(near/w) = (far - near)/far dz`, within
    /// `near/far` of it), and nothing is clipped far away.
    ///
    /// ```
    /// use microraster::{Mat4, Vec3};
    /// let p = Mat4::perspective_inv_w(1.0, 1.0, 0.5);
    /// let c = p.transform_point(Vec3::new(0.0, 0.0, -4.0));
    /// assert_eq!(((c.z / c.w + 1.0) / 2.0, c.w), (0.125, 4.0));
    /// ```
    pub fn perspective_inv_w(fov_y_radians: f32, aspect: f32, near: f32) -> Mat4 {
        Mat4::perspective_inv_w_with::<DefaultFloat>(fov_y_radians, aspect, near)
    }

    /// [`Mat4::perspective_inv_w`] with the float backend `F`.
    pub fn perspective_inv_w_with<F: FloatFns>(fov_y_radians: f32, aspect: f32, near: f32) -> Mat4 {
        let f = 1.0 / F::tan(fov_y_radians * 0.5);
        Mat4::from_rows([
            [f / aspect, 0.0, 0.0, 0.0],
            [0.0, f, 0.0, 0.0],
            [0.0, 0.0, 1.0, 2.0 * near],
            [0.0, 0.0, -1.0, 0.0],
        ])
    }

    /// A right-handed view matrix looking from `eye` at `target`, like
    /// `gluLookAt`.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
        Mat4::look_at_with::<DefaultFloat>(eye, target, up)
    }

    /// [`Mat4::look_at`] with the float backend `F`.
    pub fn look_at_with<F: FloatFns>(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
        let f = (target - eye).normalize_with::<F>();
        let s = f.cross(up).normalize_with::<F>();
        let u = s.cross(f);
        Mat4::from_rows([
            [s.x, s.y, s.z, -s.dot(eye)],
            [u.x, u.y, u.z, -u.dot(eye)],
            [-f.x, -f.y, -f.z, f.dot(eye)],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }

    /// `self * v`.
    #[cfg_attr(target_pointer_width = "64", inline)]
    pub fn mul_vec4(&self, v: Vec4) -> Vec4 {
        let c = &self.cols;
        Vec4::new(
            c[0][0] * v.x + c[1][0] * v.y + c[2][0] * v.z + c[3][0] * v.w,
            c[0][1] * v.x + c[1][1] * v.y + c[2][1] * v.z + c[3][1] * v.w,
            c[0][2] * v.x + c[1][2] * v.y + c[2][2] * v.z + c[3][2] * v.w,
            c[0][3] * v.x + c[1][3] * v.y + c[2][3] * v.z + c[3][3] * v.w,
        )
    }

    /// `self * (p, 1)`: a point to clip space.
    // (Inlined on 64-bit hosts, into the vertex stage's batches; 32-bit
    // cores keep the call, which their instruction counts of record use.)
    #[cfg_attr(target_pointer_width = "64", inline)]
    pub fn transform_point(&self, p: Vec3) -> Vec4 {
        self.mul_vec4(p.extend(1.0))
    }

    /// True if every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.cols.iter().flatten().all(|v| v.is_finite())
    }
}

impl Mul for Mat4 {
    type Output = Mat4;
    fn mul(self, o: Mat4) -> Mat4 {
        let mut cols = [[0.0; 4]; 4];
        for (c, col) in cols.iter_mut().enumerate() {
            let v = self.mul_vec4(Vec4::from_array(o.cols[c]));
            *col = [v.x, v.y, v.z, v.w];
        }
        Mat4 { cols }
    }
}

/// Degrees to radians.
pub fn radians(deg: f32) -> f32 {
    deg * (core::f32::consts::PI / 180.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `fx::min` and `fx::max` are `f32::min` and `f32::max` but for the
    /// sign of a zero result: over special values (NaN, infinities,
    /// signed zeros, subnormals) in every order, and random bit patterns.
    #[test]
    fn fx_min_max_are_the_standard_ones() {
        let special = [
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            -0.0,
            1e-45,
            -1e-45,
            1.0,
            -1.0,
            f32::MAX,
            f32::MIN,
        ];
        let mut values = special.to_vec();
        let mut x = 0x9e37_79b9u32;
        for _ in 0..if cfg!(miri) { 50 } else { 5000 } {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            values.push(f32::from_bits(x));
        }
        let same = |a: f32, b: f32| {
            a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()) || (a == 0.0 && b == 0.0)
        };
        for &a in &values {
            for &b in &special {
                for (p, q) in [(a, b), (b, a)] {
                    assert!(same(fx::min(p, q), p.min(q)), "min({p:?}, {q:?})");
                    assert!(same(fx::max(p, q), p.max(q)), "max({p:?}, {q:?})");
                }
            }
        }
        for w in values.windows(2) {
            assert!(same(fx::min(w[0], w[1]), w[0].min(w[1])));
            assert!(same(fx::max(w[0], w[1]), w[0].max(w[1])));
        }
    }

    fn close(a: Vec4, b: Vec4) -> bool {
        (a.x - b.x).abs() < 1e-5
            && (a.y - b.y).abs() < 1e-5
            && (a.z - b.z).abs() < 1e-5
            && (a.w - b.w).abs() < 1e-5
    }

    #[cfg(feature = "micromath")]
    #[test]
    fn micromath_sqrt_is_refined() {
        for x in [2.0f32, 0.5, 3.0, 1e-6, 1e6, 12345.678] {
            let r = Micromath::sqrt(x);
            let exact = (x as f64).sqrt();
            assert!(((r as f64 - exact) / exact).abs() < 1e-5, "sqrt({x}) = {r}");
        }
        assert_eq!(Micromath::sqrt(0.0), 0.0);
        // Found by fuzzing: a squared distance that overflowed to infinity
        // gave a NaN root (and a NaN bounding-sphere radius).
        assert_eq!(Micromath::sqrt(f32::INFINITY), f32::INFINITY);
        assert!(Micromath::sqrt(f32::NAN).is_nan());
        assert!(Micromath::sqrt(-1.0).is_nan());
        let big = Micromath::sqrt(f32::MAX) as f64;
        assert!((big / (f32::MAX as f64).sqrt() - 1.0).abs() < 1e-6, "{big}");
    }

    #[test]
    fn translate_then_rotate_order() {
        // R * T: the point is translated first, then rotated.
        let m = Mat4::rotation_z(radians(90.0)) * Mat4::translation(Vec3::new(1.0, 0.0, 0.0));
        let p = m.transform_point(Vec3::ZERO);
        assert!(close(p, Vec4::new(0.0, 1.0, 0.0, 1.0)), "{p:?}");
    }

    #[test]
    fn perspective_maps_near_and_far_to_minus_and_plus_w() {
        let m = Mat4::perspective(radians(60.0), 1.0, 0.5, 10.0);
        let n = m.transform_point(Vec3::new(0.0, 0.0, -0.5));
        let f = m.transform_point(Vec3::new(0.0, 0.0, -10.0));
        assert!((n.z / n.w + 1.0).abs() < 1e-5);
        assert!((f.z / f.w - 1.0).abs() < 1e-5);
    }

    #[test]
    fn look_at_puts_target_on_minus_z() {
        let v = Mat4::look_at(
            Vec3::new(0.0, 3.0, 5.0),
            Vec3::ZERO,
            Vec3::new(0.0, 1.0, 0.0),
        );
        let p = v.transform_point(Vec3::ZERO);
        assert!(p.x.abs() < 1e-5 && p.y.abs() < 1e-5 && p.z < 0.0);
    }
}
