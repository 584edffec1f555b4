//! The head's scripted path: a smooth, deterministic script of moves and turns (no keyboard, so
//! that a run reproduces). Every motion is a C²-smooth pulse that starts and ends at rest, so
//! velocities and accelerations stay finite and the head always returns home.

use glam::{DQuat, DVec3};

/// How the head moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HeadMotion {
    /// Never moves.
    Still,
    /// Slides left and right (translation along x).
    Sway,
    /// Turns about the vertical axis and back.
    Turn,
    /// Nods (pitch about the left-right axis) and back.
    Nod,
    /// Sway, turn, nod, then a rest, repeating.
    Tour,
    /// A fast shake: side to side while turning, both under a sin² window of one pulse, so it
    /// starts and ends at rest; peak accelerations of several g (see the test).
    Shake,
}

impl HeadMotion {
    pub const ALL: [(&'static str, HeadMotion); 6] = [
        ("still", HeadMotion::Still),
        ("sway", HeadMotion::Sway),
        ("turn", HeadMotion::Turn),
        ("nod", HeadMotion::Nod),
        ("tour", HeadMotion::Tour),
        ("shake", HeadMotion::Shake),
    ];
}

/// Length of one motion pulse [s]; a tour is four of them (sway, turn, nod, rest).
pub const PULSE: f64 = 2.0;
/// Sway amplitude [head radii], turn amplitude [rad], nod amplitude [rad].
const SWAY: f64 = 2.0;
const TURN: f64 = 1.0;
const NOD: f64 = 0.5;
/// Shake: sway amplitude [head radii] and frequency [Hz], turn amplitude [rad] and frequency [Hz].
/// Both frequencies are whole multiples of 1/(2 PULSE), so each oscillation is at a zero when
/// its window closes.
const SHAKE_SWAY: f64 = 1.2;
const SHAKE_SWAY_HZ: f64 = 3.0;
const SHAKE_TURN: f64 = 0.3;
const SHAKE_TURN_HZ: f64 = 2.5;

/// The shake's window on s ∈ [0, 1]: sin²(πs). Its value and slope vanish at both ends; times an
/// oscillation that is zero there, the product is C² across windows.
fn window(s: f64) -> f64 {
    let w = (std::f64::consts::PI * s.clamp(0.0, 1.0)).sin();
    w * w
}

/// A pulse on s ∈ [0, 1]: sin(2πs)·sin²(πs). It and its first two derivatives vanish at both
/// ends, so chained pulses are C² and the head starts and ends each at rest.
fn pulse(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    let w = (std::f64::consts::PI * s).sin();
    (2.0 * std::f64::consts::PI * s).sin() * w * w
}

/// Where the head is at time t: its centre [m] and its rotation (world from head frame).
/// The head frame is z up, x right, y forward; `radius` scales the sway.
pub fn head_pose(motion: HeadMotion, t: f64, radius: f64) -> (DVec3, DQuat) {
    let phase = |period_pulses: f64| (t / PULSE) % period_pulses;
    let (mut sway, mut turn, mut nod) = (0.0, 0.0, 0.0);
    match motion {
        HeadMotion::Still => {}
        HeadMotion::Sway => sway = pulse(phase(1.0)),
        HeadMotion::Turn => turn = pulse(phase(1.0)),
        HeadMotion::Nod => nod = pulse(phase(1.0)),
        HeadMotion::Shake => {
            let tau = 2.0 * std::f64::consts::PI * t;
            let w = window(phase(1.0));
            let center = DVec3::new(
                SHAKE_SWAY * radius * w * (SHAKE_SWAY_HZ * tau).sin(),
                0.0,
                0.0,
            );
            let angle = SHAKE_TURN * w * (SHAKE_TURN_HZ * tau).sin();
            return (center, DQuat::from_rotation_z(angle));
        }
        HeadMotion::Tour => {
            let p = phase(4.0);
            match p as u32 {
                0 => sway = pulse(p),
                1 => turn = pulse(p - 1.0),
                2 => nod = pulse(p - 2.0),
                _ => {}
            }
        }
    }
    let center = DVec3::new(SWAY * radius * sway, 0.0, 0.0);
    let rotation = DQuat::from_rotation_z(TURN * turn) * DQuat::from_rotation_x(NOD * nod);
    (center, rotation)
}
