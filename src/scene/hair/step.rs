//! One step of one group of strands in the strand-major layout (gauss-seidel verlet and the
//! spring methods), what every strand needs for a step, and the per-thread scratch.

use std::cell::RefCell;

use glam::{DQuat, DVec3};

use super::{HairMethod, HairParams, HairStats, WindField, lanes, spring};

/// Per-thread scratch of the solvers, made once per thread and grown when needed.
#[derive(Default)]
pub(super) struct Scratch {
    pub(super) lanes: lanes::LaneScratch,
    pub(super) spring: spring::SpringScratch,
}

thread_local! {
    pub(super) static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// What every strand needs for one step.
pub(super) struct StepContext<'a> {
    pub(super) params: &'a HairParams,
    pub(super) method: HairMethod,
    /// This (inner) step's length [s].
    pub(super) dt: f64,
    /// The whole step's length (for the kinetic energy) [s].
    pub(super) frame_dt: f64,
    /// Time at the start of the step (forces are evaluated there).
    pub(super) time: f64,
    /// Head pose at the end of the step (roots are placed there).
    pub(super) center: DVec3,
    pub(super) rotation: DQuat,
    /// Velocity kept per step, exp(-c dt).
    pub(super) keep: f64,
    pub(super) collide_radius: f64,
    /// The smallest squared distance from the centre whose square root is ≥ `collide_radius`
    /// ([`lanes::sqrt_threshold`]).
    pub(super) outside2: f64,
    /// f64::MAX, opaque to the optimiser: `r <= finite_max` tests "finite" as one vector
    /// comparison (LLVM rewrites a comparison with the constant into integer bit tests per lane).
    pub(super) finite_max: f64,
    /// The wind at `time`.
    pub(super) wind: WindField,
    /// Whether this is the first / last inner step of the step.
    pub(super) first: bool,
    pub(super) last: bool,
}

impl StepContext<'_> {
    /// Steps a group of consecutive strands in strand-major layout (`roots.len()` of them,
    /// node-major per strand) and measures the result.
    pub(super) fn step_group(
        &self,
        x: &mut [DVec3],
        prev: &mut [DVec3],
        v: &mut [DVec3],
        roots: &[DVec3],
    ) -> HairStats {
        let n = self.params.nodes;
        match self.method {
            HairMethod::Verlet => {
                for (j, root_dir) in roots.iter().enumerate() {
                    let s = j * n..(j + 1) * n;
                    self.predict_verlet(&mut x[s.clone()], &mut prev[s], *root_dir);
                }
                self.project(x, roots.len());
            }
            HairMethod::Ftl => unreachable!("ftl is stepped in lanes"),
            HairMethod::SemiImplicitEuler => {
                for (j, root_dir) in roots.iter().enumerate() {
                    let s = j * n..(j + 1) * n;
                    if self.first {
                        prev[s.clone()].copy_from_slice(&x[s.clone()]);
                    }
                    self.spring_symplectic(&mut x[s.clone()], &mut v[s], *root_dir);
                }
            }
            HairMethod::ImplicitEuler => SCRATCH.with_borrow_mut(|scratch| {
                for (j, root_dir) in roots.iter().enumerate() {
                    let s = j * n..(j + 1) * n;
                    prev[s.clone()].copy_from_slice(&x[s.clone()]);
                    self.spring_implicit(
                        &mut x[s.clone()],
                        &mut v[s],
                        *root_dir,
                        &mut scratch.spring,
                    );
                }
            }),
        }
        if self.last {
            self.measure(x, prev)
        } else {
            HairStats::default()
        }
    }

    /// The invariants of a group's new state (see [`Hair::stats`]).
    pub(super) fn measure(&self, x: &[DVec3], prev: &[DVec3]) -> HairStats {
        let n = self.params.nodes;
        let l0 = self.params.segment_length;
        let inv_l0 = 1.0 / l0;
        let inv_dt = 1.0 / self.frame_dt;
        let (mut stretch, mut depth2, mut kinetic) = (0.0f64, f64::INFINITY, 0.0f64);
        for (xs, ps) in x.chunks_exact(n).zip(prev.chunks_exact(n)) {
            kinetic += 0.5 * ((xs[0] - ps[0]) * inv_dt).length_squared();
            for k in 1..n {
                let len = (xs[k] - xs[k - 1]).length();
                stretch = stretch.max((len - l0).abs() * inv_l0);
                depth2 = depth2.min((xs[k] - self.center).length_squared());
                kinetic += 0.5 * ((xs[k] - ps[k]) * inv_dt).length_squared();
            }
        }
        HairStats::of_group(stretch, depth2, kinetic, self.collide_radius)
    }

    /// Where a root belongs at the end of the step.
    #[inline]
    pub(super) fn anchor(&self, root_dir: DVec3) -> DVec3 {
        self.center + self.rotation * (root_dir * self.params.head_radius)
    }

    /// Verlet's position update without constraints; then places the root on its anchor.
    /// `prev` ends holding the start-of-step positions.
    pub(super) fn predict_verlet(&self, x: &mut [DVec3], prev: &mut [DVec3], root_dir: DVec3) {
        let dt = self.dt;
        // Forces at the start of the step; the wind is sampled at the root (see `wind_at`).
        let a = self.params.gravity + self.params.wind_at(self.time, x[0]);
        let adt2 = a * dt * dt;
        for (x, p) in x[1..].iter_mut().zip(prev[1..].iter_mut()) {
            let next = *x + (*x - *p) * self.keep + adt2;
            *p = *x;
            *x = next;
        }
        prev[0] = x[0];
        x[0] = self.anchor(root_dir);
    }

    /// `iterations` rounds of Gauss-Seidel length projection from root to tip on `count` strands
    /// (the root fixed, other pairs corrected half each). Collision is fused into the sweep: a
    /// node is pushed out right after the last constraint that moves it in the round, so every
    /// round, and so every step, ends with no node inside the head.
    pub(super) fn project(&self, x: &mut [DVec3], count: usize) {
        let l0 = self.params.segment_length;
        let n = self.params.nodes;
        let last = n - 1;
        for _ in 0..self.params.iterations {
            for k in 1..=last {
                for j in 0..count {
                    let i = j * n + k;
                    let d = x[i] - x[i - 1];
                    let len = d.length();
                    if len > 0.0 {
                        let correction = d * ((len - l0) / len);
                        if k == 1 {
                            x[i] -= correction;
                        } else {
                            x[i - 1] += 0.5 * correction;
                            x[i] -= 0.5 * correction;
                            self.collide(&mut x[i - 1]);
                        }
                    }
                }
            }
            for j in 0..count {
                self.collide(&mut x[j * n + last]);
                // Node 1 was last moved by constraint 2; collide it too in case that one was skipped.
                self.collide(&mut x[j * n + 1]);
            }
        }
    }

    /// Pushes a node out to the collision sphere along the radius (squared distance first: most
    /// nodes are outside, and then no square root is needed).
    #[inline]
    pub(super) fn collide(&self, xk: &mut DVec3) {
        let r = *xk - self.center;
        let d2 = r.length_squared();
        let rc = self.collide_radius;
        if d2 < rc * rc && d2 > 0.0 {
            *xk = self.center + r * (rc / d2.sqrt());
        }
    }

    /// The point at rest length from `parent` nearest `predicted` that lies outside the collision
    /// sphere: the radial projection if that is outside, otherwise the nearest point of the
    /// circle where the rest-length sphere meets the collision sphere. Also returns the plain
    /// follow-the-leader point (the radial projection) for the velocity correction.
    pub(super) fn follow(&self, parent: DVec3, predicted: DVec3) -> (DVec3, DVec3) {
        let l0 = self.params.segment_length;
        let dir = (predicted - parent)
            .try_normalize()
            .unwrap_or_else(|| (parent - self.center).normalize_or(DVec3::Z));
        let candidate = parent + dir * l0;
        let rc = self.collide_radius;
        if (candidate - self.center).length() >= rc {
            return (candidate, candidate);
        }
        let axis = self.center - parent;
        let dist = axis.length();
        if dist == 0.0 {
            return (candidate, candidate);
        }
        let e = axis / dist;
        // Circle of {|y - parent| = l0} ∩ {|y - center| = rc}: centre parent + h e, radius rho.
        let h = (l0 * l0 - rc * rc + dist * dist) / (2.0 * dist);
        let rho2 = l0 * l0 - h * h;
        if rho2 < 0.0 {
            // The spheres do not meet: the rest-length sphere is all inside; go straight out.
            return (parent - e * l0, candidate);
        }
        let w = (predicted - parent) - e * (predicted - parent).dot(e);
        let w = w
            .try_normalize()
            .unwrap_or_else(|| e.any_orthonormal_vector());
        (parent + e * h + w * rho2.sqrt(), candidate)
    }
}
