//! The hair scene's physical parameters, their defaults, and what follows from them: root
//! placement, the gusting wind, the springs' default stiffness and step limit.

use glam::{DQuat, DVec3};

use super::Solver;
use super::head::{self, HeadMotion, head_pose};

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

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct HairParams {
    pub head_radius: f64,
    #[serde(rename = "head_motion")]
    pub motion: HeadMotion,
    pub strands: usize,
    /// Nodes per strand, the root included.
    pub nodes: usize,
    pub segment_length: f64,
    /// Gravitational acceleration [m/s²], z up.
    #[serde(with = "crate::scene::params::vec3")]
    pub gravity: DVec3,
    /// Wind as an acceleration on every node [m/s²].
    #[serde(with = "crate::scene::params::vec3")]
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
    /// Spring methods: stiffness per unit node mass k/m [1/s²] of every segment (given as
    /// `HairConfig::stiffness`, or following the scene).
    #[serde(skip)]
    pub stiffness: f64,
    /// Spring methods: damping per unit node mass kd/m [1/s] on the relative velocity along
    /// every segment.
    pub spring_damping: f64,
    /// Collision margin as a fraction of the head radius: nodes are pushed to R (1 + margin).
    pub margin: f64,
    /// Roots cover the cap of the head above this polar angle from the crown [rad].
    #[serde(skip)]
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
