//! Hair: strands of point masses rooted on a moving sphere (the head), with gravity, wind,
//! damping and sphere collision, stepped by four methods that really differ:
//!
//! - `verlet`: position Verlet, then the segments' length constraints, solved by `--solver`:
//!   `direct` (the chain's constraints together, Newton on the multipliers with a tridiagonal
//!   system per strand solved by the Thomas algorithm in O(nodes): [`direct`]) or `gauss-seidel`
//!   (relaxation sweeps from root to tip);
//! - `semi-implicit-euler`: force-based, each segment a stiff damped spring (as the rope models
//!   it), symplectic Euler with as many inner steps as its stability needs ([`spring`]);
//! - `implicit-euler`: the same springs, backward Euler by the rope's block-tridiagonal solve
//!   (`scene::rope::implicit`, shared, one strand at a time);
//! - `ftl`: dynamic follow-the-leader (Müller, Kim & Chentanez 2012), inextensible in one pass.
//!
//! Layout is structure-of-arrays: positions, previous positions and velocities are separate
//! arrays, and a method keeps only the arrays it needs (verlet: positions and previous
//! positions; ftl: positions and velocities; the springs all three). Two layouts (`HairState`):
//! - lane form, for `verlet` with the direct solver and `ftl`, which step eight strands at once
//!   in the lanes of a vector register ([`lanes`]): chunks of eight strands, node-major within a
//!   chunk (node k of strand s in lane s % 8 of element (s / 8)·nodes + k), stepped in place;
//! - strand-major `DVec3` (node k of strand s at s·nodes + k) for gauss-seidel verlet and the
//!   spring methods, which step one strand at a time.
//!
//! Either way the strands of a group are contiguous, so groups are stepped in parallel without
//! sharing anything. Nothing outside this module depends on the layout: positions are read
//! through [`Hair::node`], [`Hair::strand`] and [`Hair::positions`] (the recorder, the tests, the
//! invariants), so the transposition happens only where something is read. The hot loop
//! allocates nothing (per-thread scratch is made once). f64 throughout: segment lengths (~1 cm)
//! must hold to 1e-6 relative at positions ~1 m away from the origin, which f32 (7 digits)
//! cannot.

pub mod direct;
pub mod head;
pub mod lanes;
pub mod run;
pub mod simd;
pub mod spring;

use std::cell::RefCell;

use glam::{DQuat, DVec3};
use rayon::prelude::*;

use simd::{LANES, V3};

pub use head::{HeadMotion, head_pose};

/// The hair scene's methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HairMethod {
    /// Position Verlet with damping, then the length constraints (solved by `--solver`).
    Verlet,
    /// Stiff damped springs, symplectic Euler with stability substeps.
    SemiImplicitEuler,
    /// Stiff damped springs, backward Euler (block-tridiagonal Newton per strand).
    ImplicitEuler,
    /// Dynamic follow-the-leader (Müller, Kim & Chentanez 2012): inextensible in one pass.
    Ftl,
}

impl HairMethod {
    pub const ALL: [HairMethod; 4] = [
        HairMethod::Verlet,
        HairMethod::SemiImplicitEuler,
        HairMethod::ImplicitEuler,
        HairMethod::Ftl,
    ];

    /// The methods a run takes by default. The spring methods are chosen by --methods:
    /// semi-implicit-euler takes ~500 inner steps a frame at the default stiffness (a default run
    /// would take seconds more per 200 strands), and implicit-euler up to 40 Newton steps per
    /// frame, each a block-tridiagonal solve per strand.
    pub const DEFAULT: [HairMethod; 2] = [HairMethod::Verlet, HairMethod::Ftl];

    pub fn name(self) -> &'static str {
        match self {
            HairMethod::Verlet => "verlet",
            HairMethod::SemiImplicitEuler => "semi-implicit-euler",
            HairMethod::ImplicitEuler => "implicit-euler",
            HairMethod::Ftl => "ftl",
        }
    }

    /// Whether the method keeps length by stiff springs (a stated stretch bound) rather than by
    /// constraints.
    pub fn is_spring(self) -> bool {
        matches!(
            self,
            HairMethod::SemiImplicitEuler | HairMethod::ImplicitEuler
        )
    }

    pub fn description(self) -> &'static str {
        match self {
            HairMethod::Verlet => {
                "x' = x + e^(-c dt)(x - x_prev) + a dt², then the length constraints by --solver (direct: \
                 `iterations` Newton steps on the multipliers, tridiagonal per strand, their tensions \
                 applied along the end-of-step segments (one more tridiagonal solve), then an exact \
                 root-to-tip finish; gauss-seidel: `iterations` sweeps), collision fused"
            }
            HairMethod::SemiImplicitEuler => {
                "stiff damped springs: v += (a + f/m) h, x += v h, with h small enough for ω_max h < 2 \
                 (inner steps computed from the stiffness)"
            }
            HairMethod::ImplicitEuler => {
                "stiff damped springs: backward Euler, Newton on the rope's block-tridiagonal solve \
                 per strand to tolerance (at most 40 steps), each with a line search on the step's \
                 incremental potential; head contact as a stiff penalty inside the solve"
            }
            HairMethod::Ftl => {
                "DFTL: p = x + v dt, one root-to-tip pass places each node at rest length, v corrected by -0.9 d_next/dt"
            }
        }
    }
}

impl serde::Serialize for HairMethod {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> serde::Deserialize<'de> for HairMethod {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        name.parse().map_err(serde::de::Error::custom)
    }
}

impl std::str::FromStr for HairMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        HairMethod::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown hair method '{s}' (allowed: verlet, semi-implicit-euler, implicit-euler, ftl)"
                )
            })
    }
}

/// How `verlet` solves its length constraints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Solver {
    /// All of a strand's constraints together: Newton steps on the multipliers (tridiagonal,
    /// Thomas algorithm), the tension solve ([`lanes::tension_solve_lanes`]), then an exact
    /// root-to-tip finish.
    Direct,
    /// Gauss–Seidel relaxation sweeps from root to tip (position-based dynamics).
    GaussSeidel,
}

impl Solver {
    pub const ALL: [(&'static str, Solver); 2] = [
        ("direct", Solver::Direct),
        ("gauss-seidel", Solver::GaussSeidel),
    ];

    pub fn name(self) -> &'static str {
        match self {
            Solver::Direct => "direct",
            Solver::GaussSeidel => "gauss-seidel",
        }
    }
}

impl std::str::FromStr for Solver {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        crate::scene::choice(s, &Solver::ALL)
    }
}

/// Strands stepped together by one task. Each strand's constraint sweep is a chain of dependent
/// square roots and divisions (latency-bound); sweeping several strands segment by segment lets
/// the CPU overlap their chains. Per strand the arithmetic and its order are unchanged.
const GROUP: usize = 8;

/// Müller et al.'s velocity-correction factor s_damping for DFTL.
pub const FTL_CORRECTION: f64 = 0.9;

/// Newton steps implicit-euler takes at most per step (it stops earlier at the rope's
/// `NEWTON_TOL`), each with a backtracking line search on the step's incremental potential.
/// Measured (tests/hair_length.rs scenes, 40 strands, largest stretch over the four): 1.04e-2
/// with 20, 7.4e-3 with 40, 6.7e-3 with 80 (at 2.5× the cost of 40); the linearised step (1–2)
/// stretches by O(1). Not every step reaches the tolerance within the cap (cost grows with it).
pub const IMPLICIT_NEWTON_CAP: u32 = 40;

/// The spring methods' stated bound on the relative stretch |ℓ - ℓ0|/ℓ0 at the default
/// stiffness ([`HairParams::default_stiffness`]), for every head motion, size and wind.
pub const SPRING_STRETCH_BOUND: f64 = 1e-2;

/// The least default spring stiffness per unit node mass k/m [1/s²]: at the default segment
/// (0.015 m) a wave speed of 300 m/s, 410 inner steps per 60 Hz frame for semi-implicit-euler.
pub const SPRING_STIFFNESS_FLOOR: f64 = 4e8;

/// How many times the scene's speed scale ([`HairParams::speed_scale`]) the springs' wave speed
/// ℓ0·√(k/m) is at the default stiffness. A strand that is jerked, or that snaps taut, at
/// relative speed v strains its springs by about v/c (an elastic bar struck at speed v carries
/// the strain v/c), so the stretch is bounded by a fixed ratio of speed to wave speed; at this
/// ratio the largest stretch over the tested grid of head motions, sizes, strand lengths and
/// winds stays below [`SPRING_STRETCH_BOUND`].
pub const SPRING_WAVE_SPEEDS: f64 = 100.0;

#[derive(Clone, Debug, PartialEq)]
pub struct HairParams {
    pub head_radius: f64,
    pub motion: HeadMotion,
    pub strands: usize,
    /// Nodes per strand, the root included.
    pub nodes: usize,
    pub segment_length: f64,
    /// Gravitational acceleration [m/s²], z up.
    pub gravity: DVec3,
    /// Wind as an acceleration on every node [m/s²].
    pub wind: DVec3,
    /// Gust strength as a fraction of the wind (0 = steady).
    pub gust: f64,
    /// Velocity damping rate c [1/s]: velocities decay as exp(-c t) (verlet, ftl,
    /// semi-implicit-euler), or a drag force -c m v (implicit-euler).
    pub damping: f64,
    /// How verlet solves its length constraints.
    pub solver: Solver,
    /// Newton steps (verlet with the direct solver) or Gauss–Seidel sweeps (verlet with
    /// gauss-seidel) per step; implicit-euler iterates to tolerance ([`IMPLICIT_NEWTON_CAP`]).
    pub iterations: u32,
    /// Spring methods: stiffness per unit node mass k/m [1/s²] of every segment.
    pub stiffness: f64,
    /// Spring methods: damping per unit node mass kd/m [1/s] on the relative velocity along
    /// every segment.
    pub spring_damping: f64,
    /// Collision margin as a fraction of the head radius: nodes are pushed to R (1 + margin).
    pub margin: f64,
    /// Roots cover the cap of the head above this polar angle from the crown [rad].
    pub cap_angle: f64,
}

impl Default for HairParams {
    fn default() -> Self {
        HairParams {
            head_radius: 0.1,
            motion: HeadMotion::Tour,
            strands: 200,
            nodes: 16,
            segment_length: 0.015,
            gravity: DVec3::new(0.0, 0.0, -9.81),
            wind: DVec3::new(1.0, 0.0, 0.0),
            gust: 0.5,
            damping: 1.0,
            solver: Solver::Direct,
            iterations: 2,
            // The floor; a run from the command line or a scene file takes default_stiffness(),
            // which follows the other parameters.
            stiffness: SPRING_STIFFNESS_FLOOR,
            spring_damping: 2e3,
            margin: 1e-3,
            cap_angle: 0.6 * std::f64::consts::PI,
        }
    }
}

impl HairParams {
    /// Root directions in the head frame: a Fibonacci (golden-angle) spiral over the cap from the
    /// crown (z = 1) down to the polar angle `cap_angle`, evenly spread by area.
    pub fn root_directions(&self) -> Vec<DVec3> {
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let z_min = self.cap_angle.cos();
        let n = self.strands;
        (0..n)
            .map(|i| {
                let z = 1.0 - (1.0 - z_min) * (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = golden * i as f64;
                DVec3::new(r * phi.cos(), r * phi.sin(), z)
            })
            .collect()
    }

    /// Wind acceleration at time t and position x: the base vector scaled by 1 + gust·s, where s
    /// is a smooth deterministic gust signal in [-1, 1] that travels downwind. Evaluated once per
    /// strand per step (at the root): gusts vary over metres, strands are centimetres long.
    pub fn wind_at(&self, t: f64, x: DVec3) -> DVec3 {
        self.wind_field(t).at(x)
    }

    /// The wind at time t, with what does not depend on the position evaluated once.
    pub fn wind_field(&self, t: f64) -> WindField {
        WindField {
            base: self.wind,
            gust: self.gust,
            along: self.wind.normalize_or_zero(),
            t,
            slow: (2.0 * std::f64::consts::PI * 0.23 * t).sin(),
        }
    }

    /// The speed scale [m/s] at which the scene moves a strand relative to its root: the head's
    /// peak speed at a strand's reach (centre speed + angular speed · (R + L), L the strand's
    /// length, over one period of the motion, sampled every millisecond) plus the speed of a
    /// fall over R + L under gravity and the strongest gust.
    pub fn speed_scale(&self) -> f64 {
        let reach = self.head_radius + self.nodes.saturating_sub(1) as f64 * self.segment_length;
        let period = match self.motion {
            HeadMotion::Still => 0.0,
            HeadMotion::Tour => 4.0 * head::PULSE,
            _ => head::PULSE,
        };
        let h = 1e-3;
        let mut head_speed: f64 = 0.0;
        for k in 0..(period / h).round() as u32 {
            let t = k as f64 * h;
            let (c0, q0) = head_pose(self.motion, t, self.head_radius);
            let (c1, q1) = head_pose(self.motion, t + h, self.head_radius);
            let turn = (q1 * q0.inverse()).angle_between(DQuat::IDENTITY);
            head_speed = head_speed.max(((c1 - c0).length() + turn * reach) / h);
        }
        let pull = self.gravity.length() + self.wind.length() * (1.0 + self.gust);
        head_speed + (2.0 * pull * reach).sqrt()
    }

    /// The stiffness a run takes when none is given: the springs' wave speed ℓ0·√(k/m) is
    /// [`SPRING_WAVE_SPEEDS`] × [`Self::speed_scale`], and k/m at least
    /// [`SPRING_STIFFNESS_FLOOR`].
    pub fn default_stiffness(&self) -> f64 {
        let wave_speed = SPRING_WAVE_SPEEDS * self.speed_scale();
        (wave_speed / self.segment_length)
            .powi(2)
            .max(SPRING_STIFFNESS_FLOOR)
    }

    /// The longest step symplectic Euler takes on the springs: the highest mode (ω² = 4k/m,
    /// damping rate γ = 4kd/m) is stable when h²ω² + 2hγ < 4; 0.9 of that root.
    pub fn spring_step_limit(&self) -> f64 {
        let w2 = 4.0 * self.stiffness;
        let g = 4.0 * self.spring_damping;
        // Positive root of w2 h² + 2 g h - 4 = 0.
        let h = (-g + (g * g + 4.0 * w2).sqrt()) / w2;
        0.9 * h
    }
}

/// The wind at one time ([`HairParams::wind_at`]).
#[derive(Clone, Copy, Debug)]
pub struct WindField {
    base: DVec3,
    gust: f64,
    /// The unit downwind direction.
    along: DVec3,
    t: f64,
    /// The gust signal's slow factor, sin(2π·0.23·t).
    slow: f64,
}

impl WindField {
    /// The wind acceleration at x [m/s²].
    #[inline]
    pub fn at(&self, x: DVec3) -> DVec3 {
        if self.gust == 0.0 {
            return self.base;
        }
        let along = x.dot(self.along);
        let s = (2.0 * std::f64::consts::PI * (0.7 * self.t - 2.0 * along)).sin() * self.slow;
        self.base * (1.0 + self.gust * s)
    }
}

/// What one strand group measured on the state at the end of a step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GroupStats {
    /// Largest |ℓ - ℓ0|/ℓ0.
    pub stretch: f64,
    /// Deepest non-root node inside the collision sphere R(1 + margin) [m].
    pub penetration: f64,
    /// ½ Σ |Δx/dt|² over the group's nodes, in node order [J/kg].
    pub kinetic: f64,
    /// Whether every position is finite.
    pub finite: bool,
}

/// One method's copy of the hair and its head.
#[derive(Clone, Debug)]
pub struct Hair {
    pub params: HairParams,
    pub method: HairMethod,
    /// Root directions in the head frame (unit).
    roots: Vec<DVec3>,
    /// Positions and what the method keeps besides, in the method's layout: read them through
    /// [`Hair::node`], [`Hair::strand`] or [`Hair::positions`].
    state: HairState,
    /// Time of the current state [s].
    pub time: f64,
    /// The last step's length [s] (0 before the first step).
    pub last_dt: f64,
    pub head_center: DVec3,
    pub head_rotation: DQuat,
    /// Per group of strands, measured at the end of the last step.
    group_stats: Vec<GroupStats>,
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
                GroupStats {
                    finite: true,
                    ..GroupStats::default()
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

    /// The invariants measured at the end of the last step: largest stretch, deepest
    /// penetration (non-root nodes into R(1 + margin)), kinetic energy ½ Σ |Δx/dt|² per unit
    /// node mass (summed group by group in a fixed order, so it does not depend on the thread
    /// count), and whether every position is finite.
    pub fn stats(&self) -> GroupStats {
        let mut out = GroupStats {
            finite: true,
            ..GroupStats::default()
        };
        for g in &self.group_stats {
            out.stretch = out.stretch.max(g.stretch);
            out.penetration = out.penetration.max(g.penetration);
            out.kinetic += g.kinetic;
            out.finite &= g.finite;
        }
        if self.last_dt == 0.0 {
            out.kinetic = 0.0;
        }
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

    /// Kinetic energy per unit node mass, ½ Σ |Δx/dt|² [J/kg], from how far each node actually
    /// moved in the last step (the same for every method: DFTL's stored velocity carries its
    /// damping correction and is not the nodes' motion), as the step measured it
    /// ([`Hair::stats`]).
    pub fn kinetic_energy(&self) -> f64 {
        self.stats().kinetic
    }
}

/// Per-thread scratch of the solvers, made once per thread and grown when needed.
#[derive(Default)]
struct Scratch {
    lanes: lanes::LaneScratch,
    spring: spring::SpringScratch,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// What every strand needs for one step.
struct StepContext<'a> {
    params: &'a HairParams,
    method: HairMethod,
    /// This (inner) step's length [s].
    dt: f64,
    /// The whole step's length (for the kinetic energy) [s].
    frame_dt: f64,
    /// Time at the start of the step (forces are evaluated there).
    time: f64,
    /// Head pose at the end of the step (roots are placed there).
    center: DVec3,
    rotation: DQuat,
    /// Velocity kept per step, exp(-c dt).
    keep: f64,
    collide_radius: f64,
    /// The smallest squared distance from the centre whose square root is ≥ `collide_radius`
    /// ([`lanes::sqrt_threshold`]).
    outside2: f64,
    /// f64::MAX, opaque to the optimiser: `r <= finite_max` tests "finite" as one vector
    /// comparison (LLVM rewrites a comparison with the constant into integer bit tests per lane).
    finite_max: f64,
    /// The wind at `time`.
    wind: WindField,
    /// Whether this is the first / last inner step of the step.
    first: bool,
    last: bool,
}

impl StepContext<'_> {
    /// Steps a group of consecutive strands in strand-major layout (`roots.len()` of them,
    /// node-major per strand) and measures the result.
    fn step_group(
        &self,
        x: &mut [DVec3],
        prev: &mut [DVec3],
        v: &mut [DVec3],
        roots: &[DVec3],
    ) -> GroupStats {
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
            GroupStats::default()
        }
    }

    /// The invariants of a group's new state (see [`Hair::stats`]).
    fn measure(&self, x: &[DVec3], prev: &[DVec3]) -> GroupStats {
        let n = self.params.nodes;
        let l0 = self.params.segment_length;
        let inv_l0 = 1.0 / l0;
        let inv_dt = 1.0 / self.frame_dt;
        let rc = self.collide_radius;
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
        let finite = kinetic.is_finite() && stretch.is_finite();
        let penetration = if depth2 < rc * rc {
            rc - depth2.sqrt()
        } else {
            0.0
        };
        GroupStats {
            stretch,
            penetration,
            kinetic,
            finite,
        }
    }

    /// Where a root belongs at the end of the step.
    #[inline]
    fn anchor(&self, root_dir: DVec3) -> DVec3 {
        self.center + self.rotation * (root_dir * self.params.head_radius)
    }

    /// Verlet's position update without constraints; then places the root on its anchor.
    /// `prev` ends holding the start-of-step positions.
    fn predict_verlet(&self, x: &mut [DVec3], prev: &mut [DVec3], root_dir: DVec3) {
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
    fn project(&self, x: &mut [DVec3], count: usize) {
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
    fn collide(&self, xk: &mut DVec3) {
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
    fn follow(&self, parent: DVec3, predicted: DVec3) -> (DVec3, DVec3) {
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
