//! Hair: strands of point masses rooted on a moving sphere (the head), with gravity, wind,
//! damping and sphere collision, stepped by four methods that really differ:
//!
//! - `verlet`: position Verlet, then the segments' length constraints, solved by `--solver`:
//!   `direct` ([`direct`]) or `gauss-seidel` (relaxation sweeps from root to tip);
//! - `semi-implicit-euler`: force-based, each segment a stiff damped spring (as the rope models
//!   it), symplectic Euler with as many inner steps as its stability needs ([`spring`]);
//! - `implicit-euler`: the same springs, backward Euler by the rope's block-tridiagonal solve;
//! - `ftl`: dynamic follow-the-leader (Müller, Kim & Chentanez 2012), inextensible in one pass.
//!
//! Layout is structure-of-arrays, each method keeping only the arrays it needs, in one of two
//! layouts (`HairState`); the strands of a group are contiguous, so groups are stepped in
//! parallel without sharing anything. Nothing outside this module depends on the layout:
//! positions are read through [`Hair::node`], [`Hair::strand`] and [`Hair::positions`], so the
//! transposition happens only where something is read. The hot loop allocates nothing. f64
//! throughout: segment lengths (~1 cm) must hold to 1e-6 relative at positions ~1 m away from
//! the origin, which f32 (7 digits) cannot.

pub mod direct;
pub mod head;
pub mod lanes;
mod method;
mod params;
pub mod run;
pub mod simd;
pub mod spring;
mod step;

use glam::{DQuat, DVec3};
use rayon::prelude::*;

use simd::{LANES, V3};

pub use head::{HeadMotion, head_pose};
pub use method::{HairMethod, Solver};
pub use params::{
    HairParams, SPRING_STIFFNESS_FLOOR, SPRING_STRETCH_BOUND, SPRING_WAVE_SPEEDS, WindField,
};
use step::{SCRATCH, StepContext};

/// Strands stepped together by one task. Each strand's constraint sweep is a chain of dependent
/// square roots and divisions (latency-bound); sweeping several strands segment by segment lets
/// the CPU overlap their chains. Per strand the arithmetic and its order are unchanged.
const GROUP: usize = 8;

/// Müller et al.'s velocity-correction factor s_damping for DFTL.
pub const FTL_CORRECTION: f64 = 0.9;

/// Newton steps implicit-euler takes at most per step (it stops earlier at the rope's
/// `NEWTON_TOL`), each with a backtracking line search on the step's incremental potential.
/// Fewer steps leave the stiff springs visibly stretched (one or two, the linearised step,
/// stretch them by O(1)); more cost in proportion and gain little. Not every step reaches the
/// tolerance within the cap; the summary counts those that miss it.
pub const IMPLICIT_NEWTON_CAP: u32 = 40;

/// What is measured on hair at the end of a step. A strand group's (measured by the step, on
/// its way) holds ½ Σ |Δx/dt|² over the group's nodes in `kinetic_energy` and no root error;
/// [`Hair::stats`] combines the groups into the hair's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HairStats {
    /// Largest |ℓ - ℓ0|/ℓ0.
    pub max_stretch: f64,
    /// Deepest non-root node inside the collision sphere R(1 + margin) [m].
    pub max_penetration: f64,
    /// Largest distance of a root from its anchor [m].
    pub max_root_error: f64,
    /// Kinetic energy per unit mass of hair [J/kg]: ½ |Δx/dt|² averaged over every node (roots
    /// included; nodes have equal mass), so it does not grow with the strand count.
    pub kinetic_energy: f64,
    /// Whether every position is finite.
    pub finite: bool,
}

impl HairStats {
    /// A strand group's, from its largest stretch, the smallest squared distance of a non-root
    /// node from the head's centre, ½ Σ |Δx/dt|² over its nodes and the collision radius.
    pub(super) fn of_group(stretch: f64, depth2: f64, kinetic: f64, collide_radius: f64) -> Self {
        let rc = collide_radius;
        HairStats {
            max_stretch: stretch,
            max_penetration: if depth2 < rc * rc {
                rc - depth2.sqrt()
            } else {
                0.0
            },
            max_root_error: 0.0,
            kinetic_energy: kinetic,
            finite: kinetic.is_finite() && stretch.is_finite(),
        }
    }
}

/// One method's copy of the hair and its head.
#[derive(Clone, Debug)]
pub struct Hair {
    pub params: HairParams,
    pub method: HairMethod,
    /// Root directions in the head frame (unit).
    roots: Vec<DVec3>,
    /// Positions and what the method keeps besides, in the method's layout.
    state: HairState,
    /// Time of the current state [s].
    pub time: f64,
    /// The last step's length [s] (0 before the first step).
    pub last_dt: f64,
    pub head_center: DVec3,
    pub head_rotation: DQuat,
    /// Per group of strands, measured at the end of the last step.
    group_stats: Vec<HairStats>,
}

/// A method's state in its layout (module docs).
#[derive(Clone, Debug)]
enum HairState {
    /// Strand-major `DVec3` (gauss-seidel verlet and the spring methods): node k of strand s at
    /// s·nodes + k. `prev` holds the positions at the start of the last step, `vel` the
    /// velocities (spring methods; empty for verlet).
    Strands {
        pos: Vec<DVec3>,
        prev: Vec<DVec3>,
        vel: Vec<DVec3>,
    },
    /// Lane form ([`lanes`]; verlet with the direct solver, ftl): chunks of `LANES` strands,
    /// node-major within a chunk: node k of strand s in lane s % LANES of element
    /// (s / LANES)·nodes + k. The spare lanes of a partial last chunk hold copies of the chunk's
    /// first strand (stepped with it, never read). `prev` is verlet's (empty for ftl), `vel`
    /// ftl's (empty for verlet).
    Lanes {
        x: Vec<V3>,
        prev: Vec<V3>,
        vel: Vec<V3>,
    },
}

impl Hair {
    /// Strands straight out along their root normals, at rest, head at home.
    pub fn new(params: HairParams, method: HairMethod) -> Self {
        let roots = params.root_directions();
        let (center, rotation) = head_pose(params.motion, 0.0, params.head_radius);
        let n = params.nodes;
        let normals: Vec<DVec3> = roots.par_iter().map(|dir| rotation * *dir).collect();
        let start = |s: usize, k: usize| {
            center + normals[s] * (params.head_radius + k as f64 * params.segment_length)
        };
        let groups = roots.len().div_ceil(GROUP);
        let state = if lanes::in_lanes(&params, method) {
            let chunks = roots.len().div_ceil(LANES);
            // Built in parallel: the first touch of the state's pages (tens of MB at 10,000
            // strands) is a large part of a short run's setup.
            let x: Vec<V3> = (0..chunks * n)
                .into_par_iter()
                .map(|i| {
                    let (c, k) = (i / n, i % n);
                    let live = (roots.len() - c * LANES).min(LANES);
                    // Spare lanes repeat the chunk's first strand.
                    V3::from_lanes(std::array::from_fn(|l| {
                        start(c * LANES + if l < live { l } else { 0 }, k)
                    }))
                })
                .collect();
            let ftl = method == HairMethod::Ftl;
            HairState::Lanes {
                // ftl needs no previous positions (its step keeps them in scratch): a third less
                // memory traffic per frame.
                prev: if ftl {
                    Vec::new()
                } else {
                    x.par_iter().copied().collect()
                },
                vel: if ftl {
                    x.par_iter().map(|_| V3::default()).collect()
                } else {
                    Vec::new()
                },
                x,
            }
        } else {
            let mut pos = Vec::with_capacity(roots.len() * n);
            for s in 0..roots.len() {
                for k in 0..n {
                    pos.push(start(s, k));
                }
            }
            HairState::Strands {
                prev: pos.clone(),
                vel: if method == HairMethod::Verlet {
                    Vec::new()
                } else {
                    vec![DVec3::ZERO; pos.len()]
                },
                pos,
            }
        };
        Hair {
            roots,
            state,
            time: 0.0,
            last_dt: 0.0,
            head_center: center,
            head_rotation: rotation,
            group_stats: vec![
                HairStats {
                    finite: true,
                    ..HairStats::default()
                };
                groups
            ],
            params,
            method,
        }
    }

    pub fn strands(&self) -> usize {
        self.params.strands
    }

    /// Node k of strand s (k = 0 is the root).
    #[inline]
    pub fn node(&self, s: usize, k: usize) -> DVec3 {
        let n = self.params.nodes;
        match &self.state {
            HairState::Strands { pos, .. } => pos[s * n + k],
            HairState::Lanes { x, .. } => x[(s / LANES) * n + k].lane(s % LANES),
        }
    }

    /// Strand s's nodes from root to tip.
    pub fn strand(&self, s: usize) -> impl ExactSizeIterator<Item = DVec3> + '_ {
        (0..self.params.nodes).map(move |k| self.node(s, k))
    }

    /// Every position, strand-major (node k of strand s at s·nodes + k), as a copy.
    pub fn positions(&self) -> Vec<DVec3> {
        (0..self.strands()).flat_map(|s| self.strand(s)).collect()
    }

    /// Where strand s's root is attached at the current head pose.
    pub fn root_anchor(&self, s: usize) -> DVec3 {
        self.head_center + self.head_rotation * (self.roots[s] * self.params.head_radius)
    }

    /// Inner steps symplectic Euler takes within a step of dt (1 for the other methods).
    pub fn inner_steps(&self, dt: f64) -> u32 {
        if self.method == HairMethod::SemiImplicitEuler {
            (dt / self.params.spring_step_limit()).ceil().max(1.0) as u32
        } else {
            1
        }
    }

    /// Advances by dt on the current rayon pool. Each strand is independent, so the result does
    /// not depend on how strands are spread over threads. The invariants of the new state are
    /// measured on the way (while it is in cache): see [`Hair::stats`].
    pub fn step(&mut self, dt: f64) {
        let inner = self.inner_steps(dt);
        let h = dt / inner as f64;
        let p = &self.params;
        let n = p.nodes;
        let g = GROUP * n;
        let collide_radius = p.head_radius * (1.0 + p.margin);
        for j in 0..inner {
            let t0 = self.time + j as f64 * h;
            let t1 = if j + 1 == inner {
                self.time + dt
            } else {
                t0 + h
            };
            let (center, rotation) = head_pose(p.motion, t1, p.head_radius);
            let ctx = StepContext {
                params: p,
                method: self.method,
                dt: h,
                frame_dt: dt,
                time: t0,
                center,
                rotation,
                keep: (-p.damping * h).exp(),
                collide_radius,
                outside2: lanes::sqrt_threshold(collide_radius),
                finite_max: std::hint::black_box(f64::MAX),
                wind: p.wind_field(t0),
                first: j == 0,
                last: j + 1 == inner,
            };
            match &mut self.state {
                HairState::Lanes { x, prev, vel } => {
                    // A group's chunks, `nodes` lane vectors each.
                    let gl = GROUP / LANES * n;
                    let ftl = self.method == HairMethod::Ftl;
                    let kept = if ftl { vel } else { prev };
                    x.par_chunks_mut(gl)
                        .zip(kept.par_chunks_mut(gl))
                        .zip(self.roots.par_chunks(GROUP))
                        .zip(self.group_stats.par_iter_mut())
                        .for_each(|(((x, kept), roots), st)| {
                            *st = SCRATCH.with_borrow_mut(|s| {
                                if ftl {
                                    ctx.step_lanes(x, &mut [], kept, roots, &mut s.lanes)
                                } else {
                                    ctx.step_lanes(x, kept, &mut [], roots, &mut s.lanes)
                                }
                            })
                        });
                }
                HairState::Strands { pos, prev, vel } if self.method == HairMethod::Verlet => {
                    pos.par_chunks_mut(g)
                        .zip(prev.par_chunks_mut(g))
                        .zip(self.roots.par_chunks(GROUP))
                        .zip(self.group_stats.par_iter_mut())
                        .for_each(|(((x, prev), roots), st)| {
                            *st = ctx.step_group(x, prev, &mut [], roots)
                        });
                    debug_assert!(vel.is_empty());
                }
                HairState::Strands { pos, prev, vel } => {
                    pos.par_chunks_mut(g)
                        .zip(prev.par_chunks_mut(g))
                        .zip(vel.par_chunks_mut(g))
                        .zip(self.roots.par_chunks(GROUP))
                        .zip(self.group_stats.par_iter_mut())
                        .for_each(|((((x, prev), v), roots), st)| {
                            *st = ctx.step_group(x, prev, v, roots)
                        });
                }
            }
            self.head_center = center;
            self.head_rotation = rotation;
        }
        self.time += dt;
        self.last_dt = dt;
    }

    /// The invariants at the end of the last step: what the step measured on its way, plus the
    /// roots' distance from their anchors (one pass over the strands, not the nodes).
    pub fn stats(&self) -> HairStats {
        let mut out = HairStats {
            finite: true,
            ..HairStats::default()
        };
        for g in &self.group_stats {
            out.max_stretch = out.max_stretch.max(g.max_stretch);
            out.max_penetration = out.max_penetration.max(g.max_penetration);
            out.finite &= g.finite;
        }
        out.kinetic_energy =
            self.total_kinetic_energy() / (self.strands() * self.params.nodes) as f64;
        out.max_root_error = self.max_root_error();
        out
    }

    /// The largest of `f` over every strand, in parallel.
    fn max_over_strands(&self, f: impl Fn(&mut dyn Iterator<Item = DVec3>) -> f64 + Sync) -> f64 {
        (0..self.strands())
            .into_par_iter()
            .map(|s| f(&mut self.strand(s)))
            .reduce(|| 0.0, f64::max)
    }

    /// Largest |ℓ - ℓ0| / ℓ0 over all segments (a separate pass; the run uses [`Hair::stats`]).
    pub fn max_stretch(&self) -> f64 {
        let l0 = self.params.segment_length;
        self.max_over_strands(|x| {
            let mut a = x.next().unwrap_or_default();
            x.map(|b| {
                let r = ((b - a).length() - l0).abs() / l0;
                a = b;
                r
            })
            .fold(0.0, f64::max)
        })
    }

    /// Deepest penetration of any non-root node into the collision sphere R(1 + margin) [m]
    /// (roots sit on R by construction and are measured by [`Hair::max_root_error`]).
    pub fn max_penetration(&self) -> f64 {
        let c = self.head_center;
        let rc = self.params.head_radius * (1.0 + self.params.margin);
        self.max_over_strands(|x| {
            x.skip(1)
                .map(|x| (rc - (x - c).length()).max(0.0))
                .fold(0.0, f64::max)
        })
    }

    /// Largest distance of a root node from its attachment point [m].
    pub fn max_root_error(&self) -> f64 {
        (0..self.strands())
            .into_par_iter()
            .with_min_len(1024)
            .map(|s| (self.node(s, 0) - self.root_anchor(s)).length())
            .reduce(|| 0.0, f64::max)
    }

    /// Kinetic energy per unit node mass, ½ Σ |Δx/dt|² over every node [J/kg], from how far
    /// each node actually moved in the last step (the same for every method: DFTL's stored
    /// velocity carries its damping correction and is not the nodes' motion), as the step
    /// measured it, summed group by group in a fixed order (so it does not depend on the thread
    /// count).
    pub fn total_kinetic_energy(&self) -> f64 {
        if self.last_dt == 0.0 {
            return 0.0;
        }
        self.group_stats
            .iter()
            .fold(0.0, |sum, g| sum + g.kinetic_energy)
    }
}
