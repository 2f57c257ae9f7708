//! Global amplitude scaling's turn and stretch of the forcing term
//! ([`super::Scaling::Global`]), applied by [`super::Run`] at every step.

/// Global scaling (Koutras & Doulgeri 2020, their eq. 11): `x ↦
/// k·R·x` with `k = |b|/|a|` and `R` the smallest rotation taking `a` (the
/// demonstrated `g − y0`) onto `b` (the executed one), in the plane of
/// `u = a/|a|` and `v ⊥ u`: `R x = x + (c − 1)((u·x)u + (v·x)v) +
/// s((u·x)v − (v·x)u)`, `c` and `s` the angle's cosine and sine. In one
/// dimension `v = 0` and `R = c = ±1`: per-DoF scaling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Turn<const D: usize> {
    /// The DoFs turned and stretched; the others are left as they are.
    group: [bool; D],
    stretch: f32,
    u: [f32; D],
    v: [f32; D],
    cos: f32,
    sin: f32,
}

impl<const D: usize> Turn<D> {
    /// The identity on no DoF.
    const NONE: Turn<D> = Turn {
        group: [false; D],
        stretch: 1.0,
        u: [0.0; D],
        v: [0.0; D],
        cos: 1.0,
        sin: 0.0,
    };

    /// The turn and stretch of the `group`'s DoFs taking `a` onto `b`
    /// (both 0 off the group; `|a| > 0`; `b = 0` stretches to nothing).
    pub(super) fn between(group: &[bool], a: &[f32], b: &[f32]) -> Turn<D> {
        let norm = |x: &[f32]| libm::sqrtf(x.iter().map(|v| v * v).sum());
        let (na, nb) = (norm(a), norm(b));
        let mut turn = Turn {
            stretch: if na > 0.0 { nb / na } else { 1.0 },
            ..Turn::NONE
        };
        for (t, g) in turn.group.iter_mut().zip(group) {
            *t = *g;
        }
        if !(na > 0.0 && nb > 0.0) {
            return turn;
        }
        for (u, x) in turn.u.iter_mut().zip(a) {
            *u = x / na;
        }
        let cos = (turn.u.iter().zip(b))
            .map(|(u, x)| u * x / nb)
            .sum::<f32>()
            .clamp(-1.0, 1.0);
        // `v`: `b`'s direction away from `u`; where `b` is (anti)parallel,
        // any direction ⊥ `u` (the axis `u` leans least on).
        let mut v = [0.0f32; D];
        for ((v, x), u) in v.iter_mut().zip(b).zip(turn.u) {
            *v = x / nb - cos * u;
        }
        let mut sin = norm(&v);
        if sin <= 1e-6 {
            sin = 0.0;
            v = [0.0; D];
            let least = (turn.u.iter().zip(turn.group).enumerate())
                .filter(|(_, (_, g))| *g)
                .min_by(|x, y| libm::fabsf(*x.1.0).total_cmp(&libm::fabsf(*y.1.0)))
                .map(|(k, _)| k);
            if let (true, Some(k)) = (cos < 0.0, least) {
                let along = turn.u.get(k).copied().unwrap_or(0.0);
                for (j, (v, u)) in v.iter_mut().zip(turn.u).enumerate() {
                    *v = f32::from(u8::from(j == k)) - along * u;
                }
            }
            let n = norm(&v);
            for x in v.iter_mut() {
                *x = if n > 0.0 { *x / n } else { 0.0 };
            }
        } else {
            for x in v.iter_mut() {
                *x /= sin;
            }
        }
        Turn {
            v,
            cos,
            sin,
            ..turn
        }
    }

    /// `x ← k·R·x` on the group's DoFs (`u` and `v` are 0 off it).
    pub(super) fn apply(&self, x: &mut [f32; D]) {
        let dot = |w: &[f32; D], x: &[f32; D]| w.iter().zip(x).map(|(w, x)| w * x).sum::<f32>();
        let (ux, vx) = (dot(&self.u, x), dot(&self.v, x));
        for (((x, u), v), g) in x.iter_mut().zip(self.u).zip(self.v).zip(self.group) {
            if !g {
                continue;
            }
            let turned = *x + (self.cos - 1.0) * (ux * u + vx * v) + self.sin * (ux * v - vx * u);
            *x = self.stretch * turned;
        }
    }
}
