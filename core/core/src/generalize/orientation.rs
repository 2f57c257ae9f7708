//! Generalization of orientation and Cartesian DMPs over a task query:
//! `G(q)` of [`OrientationDmp`]s is an orientation DMP, with a unit goal,
//! equal to each example at its query wherever the regression interpolates
//! (GPR without noise; LWR with two examples along one query dimension).
//!
//! Every example becomes a vector, the generalizer's coefficients combine
//! the vectors, and the combination maps back to a DMP:
//! - the goal and the start orientations are tangent vectors at one
//!   reference for all examples, the mean of their goals ([`Tangent`]):
//!   continuous across ±180° and the same for `q` or `−q`; the
//!   combination maps back with the exponential map, a unit quaternion;
//! - the forcing weights are taken as they are. Each example's weights
//!   shape `e(t) = log(q(t) ⊗ ḡ)`, the rotation vector from its goal
//!   expressed in the world frame (the right-trivialized tangent space,
//!   where `q = exp(e) ⊗ g`), so a weight vector means the same turn about
//!   the goal whichever the goal is: weights of different goals are
//!   vectors of one space, combined as a position DMP's are, and nothing
//!   is transported. (Levi-Civita transport from `g` to the reference
//!   would instead rotate each example's weights by half its goal's turn
//!   from the reference, and the movement's approach to a new goal would
//!   then turn with that goal.) The log DMP's own goal stays 0;
//! - `τ` is combined as a number; the start's log coordinates relative to
//!   the new goal are taken on the side of the examples' combined ones
//!   ([`nearest_coordinates`]), so a demonstrated turn beyond 180°, and any number
//!   of whole turns, is kept.
//!
//! The examples' goals must lie within 180° of their mean for the chart to
//! hold them all (a set of goals within 90° of each other always does).
//!
//! ```
//! use primo_core::dmp::{Dmp, Shape};
//! use primo_core::generalize::Method;
//! use primo_core::generalize::orientation::OrientationGeneralizer;
//! use primo_core::orientation::OrientationDmp;
//! use primo_core::quaternion::Quaternion;
//! let yaw = |deg: f32| Quaternion::exp([0.0, 0.0, deg.to_radians()]);
//! let shape = Shape { alpha: 25.0, width: 50.0, margin: 0.0, scaled: 0 };
//! // Two examples, goals 170° and −170° yaw, a start 30° before each.
//! let example = |deg: f32| {
//!     let mut theta = [0.0; 19]; // 15 weights, goal 0, τ
//!     theta[18] = 1.0;
//!     let log = Dmp::<3, 5>::from_shape(&shape, 3, 5, &[0.0, 0.0, -0.5], &theta)?;
//!     OrientationDmp::from_parts(log, yaw(deg))
//! };
//! let (a, b) = (example(170.0)?, example(-170.0)?);
//! let g = OrientationGeneralizer::<4, 1, 32, 5>::new(
//!     Method::Lwr { bandwidth: None },
//!     &[(&[0.0], &a), (&[1.0], &b)],
//! )?;
//! // Halfway: 180°, not 0°.
//! let half = g.generalize(&[0.5])?;
//! assert!(half.goal().dot(&yaw(180.0)).abs() > 1.0 - 1e-6);
//! assert!(g.generalize(&[1.0])?.goal().dot(&yaw(-170.0)).abs() > 1.0 - 1e-6);
//! # Ok::<(), primo_core::Error>(())
//! ```

use crate::Error;
use crate::dmp::{Dmp, Shape};
use crate::error::{check_capacity, check_len};
use crate::generalize::{Generalizer, Method};
use crate::orientation::{CartesianDmp, OrientationDmp, nearest_coordinates};
use crate::quaternion::Quaternion;
use crate::tangent::Tangent;

/// Length of an orientation example's vector with `kernels` kernels:
/// `[weights row by row (3·kernels), goal (3), τ, start (3), start's log
/// coordinates (3)]`, goal and start tangent vectors at the reference.
pub const fn orientation_params(kernels: usize) -> usize {
    3 * kernels + 10
}

/// Length of a Cartesian example's vector: the position DMP's `θ`
/// (`3·kernels + 3 + 1`), its start (3), then the orientation's
/// ([`orientation_params`]).
pub const fn cartesian_params(kernels: usize) -> usize {
    3 * kernels + 7 + orientation_params(kernels)
}

/// Orientation DMPs generalized over a query: capacity `E` examples,
/// query dimension `Q`, `P` ≥ [`orientation_params`]`(kernels)`, `K`
/// kernels per axis.
#[derive(Debug, Clone)]
pub struct OrientationGeneralizer<const E: usize, const Q: usize, const P: usize, const K: usize> {
    generalizer: Generalizer<E, Q, P>,
    part: Part,
}

/// Cartesian DMPs generalized over a query, position and orientation with
/// one set of coefficients: `P` ≥ [`cartesian_params`]`(kernels)`.
#[derive(Debug, Clone)]
pub struct CartesianGeneralizer<const E: usize, const Q: usize, const P: usize, const K: usize> {
    generalizer: Generalizer<E, Q, P>,
    /// The position DMPs' shape and kernels.
    position: (Shape, usize),
    part: Part,
}

/// The orientation part of an example's vector: its reference, shape and
/// where it starts in the vector.
#[derive(Debug, Clone, Copy)]
struct Part {
    tangent: Tangent,
    shape: Shape,
    kernels: usize,
    at: usize,
    /// The examples' chart axis (one for all).
    axis: [f32; 3],
}

impl Part {
    /// The part for `dmps` (at least one; the same kernels and shape),
    /// at offset `at`.
    fn new<'a, const E: usize, const K: usize>(
        dmps: impl Iterator<Item = &'a OrientationDmp<K>>,
        at: usize,
    ) -> Result<Self, Error> {
        let mut goals = [Quaternion::IDENTITY; E];
        let mut count = 0;
        let mut first: Option<&OrientationDmp<K>> = None;
        for dmp in dmps {
            let f = *first.get_or_insert(dmp);
            same_shape(f.log_dmp(), dmp.log_dmp())?;
            if f.axis() != dmp.axis() {
                return Err(Error::OutOfRange(
                    "every example needs the first one's chart axis (turns charted about one axis)",
                ));
            }
            check_capacity("examples", count + 1, E)?;
            if let Some(g) = goals.get_mut(count) {
                *g = dmp.goal();
            }
            count += 1;
        }
        let first = first.ok_or(Error::BadState("generalization needs at least one example"))?;
        Ok(Part {
            tangent: Tangent::mean(goals.get(..count).unwrap_or(&[]))?,
            shape: first.log_dmp().shape(),
            kernels: first.log_dmp().kernels(),
            at,
            axis: first.axis(),
        })
    }

    /// Writes `dmp`'s vector ([`orientation_params`]) from `out[at..]`.
    fn write<const K: usize>(&self, dmp: &OrientationDmp<K>, out: &mut [f32]) -> Result<(), Error> {
        let k3 = 3 * self.kernels;
        let found = out.len();
        let out = out
            .get_mut(self.at..self.at + orientation_params(self.kernels))
            .ok_or(Error::Length {
                what: "orientation parameters",
                expected: self.at + orientation_params(self.kernels),
                found,
            })?;
        dmp.log_dmp().params(out)?;
        let goal = self.tangent.log(&dmp.goal());
        let start = self.tangent.log(&dmp.start_orientation());
        let turn = dmp.log_dmp().start_position();
        let parts = [(k3, &goal[..]), (k3 + 4, &start[..]), (k3 + 7, turn)];
        for (at, values) in parts {
            for (o, v) in out.iter_mut().skip(at).take(3).zip(values) {
                *o = *v;
            }
        }
        Ok(())
    }

    /// The orientation DMP of a combined vector `theta` (from `at`; its
    /// goal's three values are zeroed on the way: the log DMP's own goal).
    fn read<const K: usize>(&self, theta: &mut [f32]) -> Result<OrientationDmp<K>, Error> {
        let k3 = 3 * self.kernels;
        let len = orientation_params(self.kernels);
        let found = theta.len();
        let theta = theta.get_mut(self.at..self.at + len).ok_or(Error::Length {
            what: "orientation parameters",
            expected: self.at + len,
            found,
        })?;
        let three = |theta: &[f32], at: usize| -> [f32; 3] {
            core::array::from_fn(|i| theta.get(at + i).copied().unwrap_or(0.0))
        };
        let goal = self.tangent.exp(&three(theta, k3));
        let start = self.tangent.exp(&three(theta, k3 + 4));
        let turn = nearest_coordinates(&start, &goal, &three(theta, k3 + 7), &self.axis);
        for g in theta.iter_mut().skip(k3).take(3) {
            *g = 0.0;
        }
        let log = Dmp::from_shape(
            &self.shape,
            3,
            self.kernels,
            &turn,
            theta.get(..k3 + 4).unwrap_or(&[]),
        )?;
        OrientationDmp::from_chart(log, goal, self.axis)
    }
}

/// The same DoF, kernels and shape, or an error.
fn same_shape<const D: usize, const K: usize>(a: &Dmp<D, K>, b: &Dmp<D, K>) -> Result<(), Error> {
    if (a.dof(), a.kernels(), a.shape()) != (b.dof(), b.kernels(), b.shape()) {
        return Err(Error::OutOfRange(
            "every example needs the first one's kernels, gains, width and amplitude scaling",
        ));
    }
    Ok(())
}

impl<const E: usize, const Q: usize, const P: usize, const K: usize>
    OrientationGeneralizer<E, Q, P, K>
{
    /// Generalizes over `examples` `(q_i, dmp_i)`: every query of the first
    /// one's dimension, every DMP of the first one's kernels and shape.
    pub fn new(method: Method, examples: &[(&[f32], &OrientationDmp<K>)]) -> Result<Self, Error> {
        check_capacity("examples", examples.len(), E)?;
        let part = Part::new::<E, K>(examples.iter().map(|(_, d)| *d), 0)?;
        let len = orientation_params(part.kernels);
        check_capacity("parameter dimension", len, P)?;
        let q_dim = examples.first().map_or(0, |(q, _)| q.len());
        let mut generalizer = Generalizer::new(q_dim, len, method);
        let mut theta = [0.0f32; P];
        for (q, dmp) in examples {
            part.write(dmp, &mut theta)?;
            generalizer.add_example(q, theta.get(..len).unwrap_or(&[]))?;
        }
        generalizer.build()?;
        Ok(OrientationGeneralizer { generalizer, part })
    }

    /// The reference orientation of the goals' and starts' tangent vectors.
    pub fn reference(&self) -> Quaternion {
        self.part.tangent.reference()
    }

    /// The examples as the regression holds them: `(q_i, vector_i)` (see
    /// [`orientation_params`]).
    pub fn generalizer(&self) -> &Generalizer<E, Q, P> {
        &self.generalizer
    }

    /// `G(query)`, an orientation DMP whose execution starts at the
    /// generalized start ([`OrientationDmp::execution`]).
    pub fn generalize(&self, query: &[f32]) -> Result<OrientationDmp<K>, Error> {
        let mut theta = [0.0f32; P];
        self.generalizer.generalize(query, &mut theta)?;
        self.part.read(&mut theta)
    }
}

impl<const E: usize, const Q: usize, const P: usize, const K: usize>
    CartesianGeneralizer<E, Q, P, K>
{
    /// Generalizes over `examples` `(q_i, dmp_i)`, as
    /// [`OrientationGeneralizer::new`]; every position DMP has the first
    /// one's shape too (fit them with one [`crate::dmp::Scaling::Mask`]).
    pub fn new(method: Method, examples: &[(&[f32], &CartesianDmp<K>)]) -> Result<Self, Error> {
        check_capacity("examples", examples.len(), E)?;
        let (_, first) = examples
            .first()
            .ok_or(Error::BadState("generalization needs at least one example"))?;
        let position = &first.position;
        let at = position.param_len() + 3;
        let part = Part::new::<E, K>(examples.iter().map(|(_, d)| &d.orientation), at)?;
        let len = at + orientation_params(part.kernels);
        check_capacity("parameter dimension", len, P)?;
        check_len("position DoF", 3, position.dof())?;
        let q_dim = examples.first().map_or(0, |(q, _)| q.len());
        let mut generalizer = Generalizer::new(q_dim, len, method);
        let mut theta = [0.0f32; P];
        for (q, dmp) in examples {
            same_shape(position, &dmp.position)?;
            dmp.position.params(&mut theta)?;
            let start = dmp.position.start_position();
            for (o, s) in theta.iter_mut().skip(at - 3).zip(start) {
                *o = *s;
            }
            part.write(&dmp.orientation, &mut theta)?;
            generalizer.add_example(q, theta.get(..len).unwrap_or(&[]))?;
        }
        generalizer.build()?;
        Ok(CartesianGeneralizer {
            generalizer,
            position: (position.shape(), position.kernels()),
            part,
        })
    }

    /// The reference orientation of the goals' and starts' tangent vectors.
    pub fn reference(&self) -> Quaternion {
        self.part.tangent.reference()
    }

    /// `G(query)`: position and orientation, starting at the generalized
    /// starts.
    pub fn generalize(&self, query: &[f32]) -> Result<CartesianDmp<K>, Error> {
        let mut theta = [0.0f32; P];
        self.generalizer.generalize(query, &mut theta)?;
        let at = self.part.at;
        let (shape, kernels) = self.position;
        let position = Dmp::from_shape(
            &shape,
            3,
            kernels,
            theta.get(at - 3..at).unwrap_or(&[]),
            theta.get(..at - 3).unwrap_or(&[]),
        )?;
        Ok(CartesianDmp {
            position,
            orientation: self.part.read(&mut theta)?,
        })
    }
}
