//! The mass-spring rope: N point masses on a line, Hooke springs between neighbours (rest length =
//! initial spacing), spring damping along each spring, air drag, gravity, pinned nodes. f64.
//!
//! Coordinates are flat: node i occupies `x[3i..3i+3]`, z up like every scene (gravity
//! defaults to (0, 0, −9.81)). Pinned nodes have zero acceleration and start at rest, so every
//! method keeps them exactly where they were placed.
//!
//! The energy balance (DESIGN principle 7): a damped rope made with [`Rope::balanced`] carries
//! one more coordinate, the work W the damping and drag have dissipated, as a *velocity*
//! component whose "acceleration" is the dissipated power P(x, v) = Σ kd (Δv·u)² + Σ ka |v|²
//! (its position component is unused). Every method then integrates W' = P with its own stages
//! and weights, exactly as it integrates v' = a(x, v) (Verlet through its velocity identity,
//! exempt from its damping factor: [`SecondOrderSystem::first_order_tail`]; implicit Euler by
//! W1 = W0 + h P(x1, v1) after its Newton solve). So W has the method's order on these forces and
//! E + W − E0 converges at it; a quadrature of P at the samples would not.

pub mod implicit;
pub mod run;

use std::sync::{Mutex, PoisonError};

use glam::DVec3;

use crate::integrate::{ImplicitSolve, Integrator, SecondOrderSystem};
use implicit::Workspace;

/// Physical parameters and initial layout of the rope.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct RopeParams {
    /// Number of point masses, ≥ 2.
    pub nodes: usize,
    /// First node's position [m].
    #[serde(with = "crate::scene::params::vec3")]
    pub start: DVec3,
    /// Last node's position [m]; the others are spaced evenly in between.
    #[serde(with = "crate::scene::params::vec3")]
    pub end: DVec3,
    /// Mass of each node [kg].
    pub mass: f64,
    /// Hooke stiffness ks of every spring [N/m].
    pub stiffness: f64,
    /// Damping kd on the relative velocity along each spring [N·s/m].
    pub spring_damping: f64,
    /// Air drag ka: force -ka v on every node [N·s/m].
    pub air_drag: f64,
    /// Gravitational acceleration [m/s²], z up.
    #[serde(with = "crate::scene::params::vec3")]
    pub gravity: DVec3,
    /// Indices of nodes held fixed.
    pub pinned: Vec<usize>,
    /// Newton iterations per implicit-Euler step: 1 = linearised backward Euler (Baraff–Witkin);
    /// more refine towards the exact backward-Euler solution, stopping early at tolerance.
    pub newton_iterations: u32,
}

impl Default for RopeParams {
    fn default() -> Self {
        RopeParams {
            nodes: 16,
            start: DVec3::ZERO,
            end: DVec3::new(4.0, 0.0, 0.0),
            mass: 0.1,
            stiffness: 5000.0,
            spring_damping: 0.05,
            air_drag: 0.01,
            gravity: DVec3::new(0.0, 0.0, -9.81),
            pinned: vec![0],
            newton_iterations: 1,
        }
    }
}

impl RopeParams {
    /// Whether the forces depend on the velocity: spring damping or air drag above 0.
    pub fn velocity_dependent(&self) -> bool {
        self.spring_damping != 0.0 || self.air_drag != 0.0
    }

    /// Rest length of every spring: the initial spacing [m].
    pub fn rest_length(&self) -> f64 {
        (self.end - self.start).length() / (self.nodes - 1) as f64
    }

    /// Initial positions, evenly spaced from start to end (flat, 3 per node).
    pub fn initial_positions(&self) -> Vec<f64> {
        (0..self.nodes)
            .flat_map(|i| {
                let p = self
                    .start
                    .lerp(self.end, i as f64 / (self.nodes - 1) as f64);
                [p.x, p.y, p.z]
            })
            .collect()
    }

    /// Highest angular frequency of the linearised springs [rad/s], and whether it is exact:
    /// the pinned-free chain's exact value when only node 0 is pinned, otherwise the bound
    /// 2 sqrt(k/m) that holds for any pinning.
    pub fn omega_max(&self) -> (f64, bool) {
        if self.pinned == [0] {
            (self.omega_max_pinned_free(), true)
        } else {
            (2.0 * (self.stiffness / self.mass).sqrt(), false)
        }
    }

    /// Highest angular frequency of the linearised chain with its first node pinned and the last
    /// free (N-1 moving masses): 2 sqrt(k/m) sin((2M-1)π / (2(2M+1))), M = N-1
    /// (oscillator_theory.md). Always below 2 sqrt(k/m).
    pub fn omega_max_pinned_free(&self) -> f64 {
        let m = (self.nodes - 1) as f64;
        2.0 * (self.stiffness / self.mass).sqrt()
            * ((2.0 * m - 1.0) * std::f64::consts::PI / (2.0 * (2.0 * m + 1.0))).sin()
    }
}

/// Node i's position or velocity from flat coordinates.
#[inline]
pub fn node(x: &[f64], i: usize) -> DVec3 {
    DVec3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2])
}

#[inline]
fn add_to(x: &mut [f64], i: usize, v: DVec3) {
    x[3 * i] += v.x;
    x[3 * i + 1] += v.y;
    x[3 * i + 2] += v.z;
}

/// Σ x² as four interleaved sums, which the compiler keeps in vector registers (one running sum
/// would wait an addition's latency per coordinate): the drag's share of the dissipated power.
fn sum_of_squares(x: &[f64]) -> f64 {
    let quads = x.chunks_exact(4);
    let rest: f64 = quads.remainder().iter().map(|c| c * c).sum();
    let s = quads.fold([0.0; 4], |s, q| std::array::from_fn(|j| s[j] + q[j] * q[j]));
    (s[0] + s[1]) + (s[2] + s[3]) + rest
}

/// The rope as a [`SecondOrderSystem`] over 3N coordinates.
#[derive(Debug)]
pub struct Rope {
    pub params: RopeParams,
    rest: f64,
    pinned: Vec<bool>,
    /// Scratch for the implicit solve, allocated at its first step (about 500 B per node, which
    /// a run without an implicit method does not need). Behind a lock so that lanes can step
    /// side by side; only the implicit lane takes it.
    workspace: Mutex<Option<Workspace>>,
    /// Whether the dissipated work is the last coordinate (see the module docs).
    work: bool,
}

impl Rope {
    /// Panics on parameters `app` validation refuses (fewer than 2 nodes, pinned index out of range).
    pub fn new(params: RopeParams) -> Self {
        assert!(params.nodes >= 2, "a rope has at least 2 nodes");
        let mut pinned = vec![false; params.nodes];
        for &p in &params.pinned {
            pinned[p] = true;
        }
        Rope {
            rest: params.rest_length(),
            workspace: Mutex::new(None),
            pinned,
            params,
            work: false,
        }
    }

    /// The rope with its dissipated work W as one more coordinate when it is damped (see the
    /// module docs); an undamped rope is [`Rope::new`]'s, at no cost.
    pub fn balanced(params: RopeParams) -> Self {
        let mut rope = Rope::new(params);
        rope.work = rope.params.velocity_dependent();
        rope
    }

    /// Whether the dissipated work is integrated (a damped [`Rope::balanced`]).
    pub fn tracks_work(&self) -> bool {
        self.work
    }

    /// The start at rest in the layout: the initial positions, zero velocities, and W = 0 with
    /// its unused position when the work is tracked.
    pub fn start(&self) -> (Vec<f64>, Vec<f64>) {
        let mut x0 = self.params.initial_positions();
        if self.work {
            x0.push(0.0);
        }
        let v0 = vec![0.0; x0.len()];
        (x0, v0)
    }

    /// The dissipated work W [J] in a state (0 when it is not tracked).
    pub fn work(&self, v: &[f64]) -> f64 {
        if self.work {
            v[3 * self.params.nodes]
        } else {
            0.0
        }
    }

    /// The power the damping and drag take out [W], Σ kd (Δv·d)²/|d|² + Σ ka |v|²: what
    /// [`Rope::forces`] adds up with `POWER`, without the forces (no square root).
    fn dissipated_power(&self, x: &[f64], v: &[f64]) -> f64 {
        let p = &self.params;
        let along: f64 = (0..p.nodes - 1)
            .map(|i| {
                let d = node(x, i + 1) - node(x, i);
                let dot = (node(v, i + 1) - node(v, i)).dot(d);
                let len2 = d.length_squared();
                if len2 == 0.0 { 0.0 } else { dot * dot / len2 }
            })
            .sum();
        p.air_drag * sum_of_squares(v) + p.spring_damping * along
    }

    pub fn nodes(&self) -> usize {
        self.params.nodes
    }

    pub fn is_pinned(&self, i: usize) -> bool {
        self.pinned[i]
    }

    pub fn rest(&self) -> f64 {
        self.rest
    }

    /// Total force on every node (flat), before pinning.
    pub fn forces(&self, x: &[f64], v: &[f64], f: &mut [f64]) {
        self.forces_with::<false>(x, v, f);
    }

    /// [`Rope::forces`], and with `POWER` the dissipated power: the springs' share in their pass
    /// (it shares their direction and relative velocity), the drag's by [`sum_of_squares`]
    /// (pinned nodes are at rest: no share). Never inlined, so the force loops compile alike with
    /// and without it: inlined, they did not vectorise (`benches/rope_step.rs`).
    #[inline(never)]
    fn forces_with<const POWER: bool>(&self, x: &[f64], v: &[f64], f: &mut [f64]) -> f64 {
        let p = &self.params;
        for i in 0..p.nodes {
            let fi = p.mass * p.gravity - p.air_drag * node(v, i);
            f[3 * i] = fi.x;
            f[3 * i + 1] = fi.y;
            f[3 * i + 2] = fi.z;
        }
        let mut along2 = 0.0;
        for i in 0..p.nodes - 1 {
            let (fs, along) = self.spring_force(x, v, i);
            along2 += along * along; // dead code without POWER
            add_to(f, i, fs);
            add_to(f, i + 1, -fs);
        }
        if POWER {
            p.air_drag * sum_of_squares(&v[..3 * p.nodes]) + p.spring_damping * along2
        } else {
            0.0
        }
    }

    /// Force of spring i (nodes i, i+1) on node i: Hooke along the spring plus damping of the
    /// relative velocity's component along it, and that component. Node i+1 feels the opposite.
    #[inline]
    fn spring_force(&self, x: &[f64], v: &[f64], i: usize) -> (DVec3, f64) {
        let d = node(x, i + 1) - node(x, i);
        let len = d.length();
        if len == 0.0 {
            return (DVec3::ZERO, 0.0); // direction undefined; only reachable by a blown-up method
        }
        let u = d / len;
        let along = (node(v, i + 1) - node(v, i)).dot(u);
        let tension = self.params.stiffness * (len - self.rest);
        ((tension + self.params.spring_damping * along) * u, along)
    }

    /// Kinetic + spring + gravitational energy [J], gravity's zero at the origin.
    pub fn energy(&self, x: &[f64], v: &[f64]) -> f64 {
        self.energy_and_strain(x, v).0
    }

    /// Kinetic + spring energy [J]: the energy in motion and stretch, without gravity.
    pub fn kinetic_and_elastic_energy(&self, x: &[f64], v: &[f64]) -> f64 {
        let p = &self.params;
        let kinetic: f64 = (0..p.nodes)
            .map(|i| 0.5 * p.mass * node(v, i).length_squared())
            .sum();
        let elastic: f64 = (0..p.nodes - 1)
            .map(|i| {
                let stretch = (node(x, i + 1) - node(x, i)).length() - self.rest;
                0.5 * p.stiffness * stretch * stretch
            })
            .sum();
        kinetic + elastic
    }

    /// Total energy and largest strain (as [`Rope::max_strain`]) in one pass that takes each
    /// spring's length once: the check every step of a run pays.
    pub fn energy_and_strain(&self, x: &[f64], v: &[f64]) -> (f64, f64) {
        let p = &self.params;
        // -0.0 is the neutral element `Iterator::sum` starts from, so the sums match `energy`.
        let (mut kinetic, mut elastic, mut gravity, mut strain) = (-0.0, -0.0, -0.0, 0.0f64);
        for i in 0..p.nodes {
            kinetic += 0.5 * p.mass * node(v, i).length_squared();
            gravity += -p.mass * p.gravity.dot(node(x, i));
        }
        for i in 0..p.nodes - 1 {
            let stretch = (node(x, i + 1) - node(x, i)).length() - self.rest;
            elastic += 0.5 * p.stiffness * stretch * stretch;
            strain = strain.max(stretch.abs() / self.rest);
        }
        (kinetic + elastic + gravity, strain)
    }

    /// Largest |ℓ - ℓ0| / ℓ0 over the springs.
    pub fn max_strain(&self, x: &[f64]) -> f64 {
        (0..self.params.nodes - 1)
            .map(|i| ((node(x, i + 1) - node(x, i)).length() - self.rest).abs() / self.rest)
            .fold(0.0, f64::max)
    }
}

impl SecondOrderSystem for Rope {
    fn dim(&self) -> usize {
        3 * self.params.nodes + usize::from(self.work)
    }

    fn first_order_tail(&self) -> usize {
        usize::from(self.work)
    }

    fn acceleration(&self, x: &[f64], v: &[f64], a: &mut [f64]) {
        let n3 = 3 * self.params.nodes;
        if self.work {
            a[n3] = self.forces_with::<true>(x, v, &mut a[..n3]);
        } else {
            self.forces(x, v, a);
        }
        let inv_m = 1.0 / self.params.mass;
        for (i, ai) in a[..n3].chunks_exact_mut(3).enumerate() {
            if self.pinned[i] {
                ai.fill(0.0);
            } else {
                ai.iter_mut().for_each(|c| *c *= inv_m);
            }
        }
    }

    fn implicit_euler_step(&self, x: &mut [f64], v: &mut [f64], dt: f64) -> ImplicitSolve {
        let mut workspace = self
            .workspace
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        let workspace = workspace.get_or_insert_with(|| Workspace::new(self.params.nodes));
        let n3 = 3 * self.params.nodes;
        let solve = implicit::backward_euler_step(self, workspace, &mut x[..n3], &mut v[..n3], dt);
        if self.work {
            // Backward Euler on W' = P too: W1 = W0 + h P(x1, v1) (and its unused position).
            v[n3] += dt * self.dissipated_power(&x[..n3], &v[..n3]);
            x[n3] += dt * v[n3];
        }
        solve
    }
}

/// Takes `steps` steps. The loop the lab times and the benchmark measures: not generic and never
/// inlined, so both run the same machine code (see `pendulum::step_block`).
#[inline(never)]
pub fn step_rope(it: &mut Integrator, rope: &Rope, steps: u64) {
    for _ in 0..steps {
        it.step(rope);
    }
}
