//! Three-vectors of `f32`: the few operations orientations and obstacles
//! share.

/// `a x + b y`.
pub(crate) fn mix(a: f32, x: &[f32; 3], b: f32, y: &[f32; 3]) -> [f32; 3] {
    let ([x0, x1, x2], [y0, y1, y2]) = (x, y);
    [a * x0 + b * y0, a * x1 + b * y1, a * x2 + b * y2]
}

/// Euclidean norm.
pub(crate) fn norm(v: &[f32; 3]) -> f32 {
    libm::sqrtf(dot(v, v))
}

/// Dot product.
pub(crate) fn dot(a: &[f32; 3], b: &[f32; 3]) -> f32 {
    let ([a0, a1, a2], [b0, b1, b2]) = (a, b);
    a0 * b0 + a1 * b1 + a2 * b2
}

/// Cross product.
pub(crate) fn cross(a: &[f32; 3], b: &[f32; 3]) -> [f32; 3] {
    let ([a0, a1, a2], [b0, b1, b2]) = (a, b);
    [a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0]
}
