//! Hair: strands of point masses rooted on a moving sphere (the head), with gravity, wind,
//! damping, inextensible segments and sphere collision, stepped by position-based methods.
//!
//! Layout is structure-of-arrays: positions, previous positions and velocities are separate
//! arrays, strand-major (node k of strand s at s·nodes + k), so each strand is a contiguous slice
//! of every array and strands are stepped in parallel without sharing anything. The hot loop
//! allocates nothing. f64 throughout: segment lengths (~1 cm) must hold to 1e-6 relative at
//! positions ~1 m away from the origin, which f32 (7 digits) cannot.

pub mod head;
pub mod run;

use glam::{DQuat, DVec3};
use rayon::prelude::*;

pub use head::{HeadMotion, head_pose};

/// The position-based methods the hair scene offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HairMethod {
    /// Position Verlet with damping, then constraint projection (the seeds).
    Verlet,
    /// Position-based dynamics: predict with the velocity, project, velocity from positions.
    SemiImplicitEuler,
    /// Dynamic follow-the-leader (Müller, Kim & Chentanez 2012): inextensible in one pass.
    Ftl,
}

impl HairMethod {
    pub const ALL: [HairMethod; 3] = [
        HairMethod::Verlet,
        HairMethod::SemiImplicitEuler,
        HairMethod::Ftl,
    ];

    pub fn name(self) -> &'static str {
        match self {
            HairMethod::Verlet => "verlet",
            HairMethod::SemiImplicitEuler => "semi-implicit-euler",
            HairMethod::Ftl => "ftl",
        }
    }

    pub fn description(self) -> &'static str {
        match self {
            HairMethod::Verlet => {
                "x' = x + (1-d)(x - x_prev) + a dt², then `iterations` rounds of length + collision projection"
            }
            HairMethod::SemiImplicitEuler => {
                "PBD: v += a dt, p = x + v dt, `iterations` rounds of projection, v = (p - x)/dt"
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
                format!("unknown hair method '{s}' (allowed: verlet, semi-implicit-euler, ftl)")
            })
    }
}

/// Strands stepped together by one task. Each strand's constraint sweep is a chain of dependent
/// square roots and divisions (latency-bound); sweeping several strands segment by segment lets
/// the CPU overlap their chains. Per strand the arithmetic and its order are unchanged.
const GROUP: usize = 8;

/// Müller et al.'s velocity-correction factor s_damping for DFTL.
pub const FTL_CORRECTION: f64 = 0.9;

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
    /// Velocity damping rate c [1/s]: velocities decay as exp(-c t) between constraints.
    pub damping: f64,
    /// Constraint-projection rounds per step (verlet, semi-implicit-euler).
    pub iterations: u32,
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
            iterations: 4,
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
        if self.gust == 0.0 {
            return self.wind;
        }
        let along = x.dot(self.wind.normalize_or_zero());
        let s = (2.0 * std::f64::consts::PI * (0.7 * t - 2.0 * along)).sin()
            * (2.0 * std::f64::consts::PI * 0.23 * t).sin();
        self.wind * (1.0 + self.gust * s)
    }
}

/// One method's copy of the hair and its head.
#[derive(Clone, Debug)]
pub struct Hair {
    pub params: HairParams,
    pub method: HairMethod,
    /// Root directions in the head frame (unit).
    roots: Vec<DVec3>,
    pub pos: Vec<DVec3>,
    pub prev: Vec<DVec3>,
    pub vel: Vec<DVec3>,
    /// Time of the current state [s].
    pub time: f64,
    /// The last step's length [s] (0 before the first step).
    pub last_dt: f64,
    pub head_center: DVec3,
    pub head_rotation: DQuat,
}

impl Hair {
    /// Strands straight out along their root normals, at rest, head at home.
    pub fn new(params: HairParams, method: HairMethod) -> Self {
        let roots = params.root_directions();
        let (center, rotation) = head_pose(params.motion, 0.0, params.head_radius);
        let n = params.nodes;
        let mut pos = Vec::with_capacity(roots.len() * n);
        for dir in &roots {
            let d = rotation * *dir;
            for k in 0..n {
                pos.push(center + d * (params.head_radius + k as f64 * params.segment_length));
            }
        }
        let total = pos.len();
        Hair {
            roots,
            prev: pos.clone(),
            vel: vec![DVec3::ZERO; total],
            pos,
            time: 0.0,
            last_dt: 0.0,
            head_center: center,
            head_rotation: rotation,
            params,
            method,
        }
    }

    pub fn strands(&self) -> usize {
        self.params.strands
    }

    /// Where strand s's root is attached at the current head pose.
    pub fn root_anchor(&self, s: usize) -> DVec3 {
        self.head_center + self.head_rotation * (self.roots[s] * self.params.head_radius)
    }

    /// Advances by dt on the current rayon pool. Each strand is independent, so the result does
    /// not depend on how strands are spread over threads.
    pub fn step(&mut self, dt: f64) {
        let t1 = self.time + dt;
        let p = &self.params;
        let (center, rotation) = head_pose(p.motion, t1, p.head_radius);
        let ctx = StepContext {
            params: p,
            method: self.method,
            dt,
            time: self.time,
            center,
            rotation,
            keep: (-p.damping * dt).exp(),
            collide_radius: p.head_radius * (1.0 + p.margin),
        };
        let n = p.nodes;
        let g = GROUP * n;
        self.pos
            .par_chunks_mut(g)
            .zip(self.prev.par_chunks_mut(g))
            .zip(self.vel.par_chunks_mut(g))
            .zip(self.roots.par_chunks(GROUP))
            .for_each(|(((x, prev), v), roots)| ctx.step_group(x, prev, v, roots));
        self.time = t1;
        self.last_dt = dt;
        self.head_center = center;
        self.head_rotation = rotation;
    }

    /// Largest |ℓ - ℓ0| / ℓ0 over all segments.
    pub fn max_stretch(&self) -> f64 {
        let l0 = self.params.segment_length;
        self.pos
            .par_chunks(self.params.nodes)
            .map(|x| {
                x.windows(2)
                    .map(|w| ((w[1] - w[0]).length() - l0).abs() / l0)
                    .fold(0.0, f64::max)
            })
            .reduce(|| 0.0, f64::max)
    }

    /// Deepest penetration of any node into the head sphere (radius R, not R + margin) [m].
    pub fn max_penetration(&self) -> f64 {
        let (c, r) = (self.head_center, self.params.head_radius);
        self.pos
            .par_iter()
            .map(|x| (r - (*x - c).length()).max(0.0))
            .reduce(|| 0.0, f64::max)
    }

    /// Largest distance of a root node from its attachment point [m].
    pub fn max_root_error(&self) -> f64 {
        (0..self.strands())
            .map(|s| (self.pos[s * self.params.nodes] - self.root_anchor(s)).length())
            .fold(0.0, f64::max)
    }

    /// Kinetic energy per unit node mass, ½ Σ |Δx/dt|² [J/kg], from how far each node actually
    /// moved in the last step (the same for every method: DFTL's stored velocity carries its
    /// damping correction and is not the nodes' motion). Summed in a fixed order, so the value
    /// does not depend on the thread count.
    pub fn kinetic_energy(&self) -> f64 {
        if self.last_dt == 0.0 {
            return 0.0;
        }
        let inv = 1.0 / self.last_dt;
        let per_strand: Vec<f64> = self
            .pos
            .par_chunks(self.params.nodes)
            .zip(self.prev.par_chunks(self.params.nodes))
            .map(|(x, p)| {
                x.iter()
                    .zip(p)
                    .map(|(x, p)| 0.5 * ((*x - *p) * inv).length_squared())
                    .sum()
            })
            .collect();
        per_strand.iter().sum()
    }
}

/// What every strand needs for one step.
struct StepContext<'a> {
    params: &'a HairParams,
    method: HairMethod,
    dt: f64,
    /// Time at the start of the step (forces are evaluated there).
    time: f64,
    /// Head pose at the end of the step (roots are placed there).
    center: DVec3,
    rotation: DQuat,
    /// Velocity kept per step, exp(-c dt).
    keep: f64,
    collide_radius: f64,
}

impl StepContext<'_> {
    /// Steps a group of consecutive strands (`roots.len()` of them, node-major per strand).
    fn step_group(&self, x: &mut [DVec3], prev: &mut [DVec3], v: &mut [DVec3], roots: &[DVec3]) {
        let n = self.params.nodes;
        let dt = self.dt;
        for (j, root_dir) in roots.iter().enumerate() {
            let s = j * n..(j + 1) * n;
            self.predict(
                &mut x[s.clone()],
                &mut prev[s.clone()],
                &mut v[s],
                *root_dir,
            );
        }
        match self.method {
            HairMethod::Verlet | HairMethod::SemiImplicitEuler => {
                self.project(x, roots.len());
                for ((v, x), p) in v.iter_mut().zip(x.iter()).zip(prev.iter()) {
                    *v = (*x - *p) / dt;
                }
            }
            HairMethod::Ftl => {
                self.follow_the_leader(x, v, roots.len());
                // Velocities from positions, with the DFTL correction -s d_{k+1}/dt (v holds d).
                for j in 0..roots.len() {
                    let (x, p, v) = (
                        &x[j * n..(j + 1) * n],
                        &prev[j * n..(j + 1) * n],
                        &mut v[j * n..(j + 1) * n],
                    );
                    let last = n - 1;
                    for k in 0..=last {
                        let correction = if k < last && k > 0 {
                            v[k + 1]
                        } else {
                            DVec3::ZERO
                        };
                        v[k] = (x[k] - p[k]) / dt - FTL_CORRECTION * correction / dt;
                    }
                }
            }
        }
    }

    /// Moves one strand without its constraints: Verlet's position update, or the velocity
    /// update and prediction of PBD and DFTL; then places the root on its anchor. `prev` ends
    /// holding the start-of-step positions.
    fn predict(&self, x: &mut [DVec3], prev: &mut [DVec3], v: &mut [DVec3], root_dir: DVec3) {
        let dt = self.dt;
        // Forces at the start of the step; the wind is sampled at the root (see `wind_at`).
        let a = self.params.gravity + self.params.wind_at(self.time, x[0]);
        match self.method {
            HairMethod::Verlet => {
                for k in 1..x.len() {
                    let next = x[k] + (x[k] - prev[k]) * self.keep + a * dt * dt;
                    prev[k] = x[k];
                    x[k] = next;
                }
            }
            HairMethod::SemiImplicitEuler | HairMethod::Ftl => {
                for k in 1..x.len() {
                    v[k] = (v[k] + a * dt) * self.keep;
                    prev[k] = x[k];
                    x[k] += v[k] * dt;
                }
            }
        }
        prev[0] = x[0];
        x[0] = self.center + self.rotation * (root_dir * self.params.head_radius);
    }

    /// DFTL's single pass over `count` strands, segment by segment: each node moves onto the
    /// sphere of rest length around its (already final) parent, and out of the head along that
    /// sphere. `v` receives each node's length correction d_k (without the collision's share,
    /// which the velocity correction must not feed back into the parent).
    fn follow_the_leader(&self, x: &mut [DVec3], v: &mut [DVec3], count: usize) {
        let n = self.params.nodes;
        for k in 1..n {
            for j in 0..count {
                let i = j * n + k;
                let predicted = x[i];
                let (placed, followed) = self.follow(x[i - 1], predicted);
                x[i] = placed;
                v[i] = followed - predicted;
            }
        }
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
