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
    /// A fast shake: side to side at 3 Hz (±1.2 head radii) while turning at 2.5 Hz (±0.3 rad),
    /// both under a sin² window of 2 s, so it starts and ends at rest; peak accelerations of
    /// several g (see the test), smooth (C²) and deterministic.
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_motion_starts_and_ends_at_home_at_rest() {
        for m in [
            HeadMotion::Sway,
            HeadMotion::Turn,
            HeadMotion::Nod,
            HeadMotion::Tour,
            HeadMotion::Shake,
        ] {
            let period = if m == HeadMotion::Tour {
                4.0 * PULSE
            } else {
                PULSE
            };
            for t in [0.0, period, 2.0 * period] {
                let (c, q) = head_pose(m, t, 0.1);
                assert!(
                    c.length() < 1e-12 && q.angle_between(DQuat::IDENTITY) < 1e-12,
                    "{m:?} at {t}"
                );
                // Velocity by central difference vanishes at the joints.
                let e = 1e-4;
                let (c1, _) = head_pose(m, t + e, 0.1);
                let (c0, _) = head_pose(m, (t - e).max(0.0), 0.1);
                assert!((c1 - c0).length() / (2.0 * e) < 1e-6, "{m:?} moving at {t}");
            }
        }
    }

    #[test]
    fn acceleration_stays_bounded() {
        // Second differences of the sway over a tour stay near the analytic bound
        // max |pulse''| · SWAY·R / PULSE² (pulse'' ≤ ~4π² · 1.2).
        let (r, h) = (0.1, 1e-3);
        let bound = 4.0 * std::f64::consts::PI.powi(2) * 1.5 * SWAY * r / (PULSE * PULSE);
        for k in 1..8000 {
            let t = k as f64 * h;
            let x = |t: f64| head_pose(HeadMotion::Tour, t, r).0.x;
            let acc = (x(t + h) - 2.0 * x(t) + x(t - h)) / (h * h);
            assert!(acc.abs() < bound, "acceleration {acc} at t = {t}");
        }
    }

    #[test]
    fn shake_accelerates_by_several_g() {
        // Peak acceleration of the centre and of a root at the side of the head (radius R).
        let (r, h) = (0.1, 1e-4);
        let point = |t: f64| {
            let (c, q) = head_pose(HeadMotion::Shake, t, r);
            c + q * DVec3::new(0.0, r, 0.0)
        };
        let mut peak: f64 = 0.0;
        for k in 1..20_000 {
            let t = k as f64 * h;
            let acc = (point(t + h) - 2.0 * point(t) + point(t - h)) / (h * h);
            peak = peak.max(acc.length());
        }
        assert!(peak > 3.0 * 9.81 && peak < 10.0 * 9.81, "peak {peak} m/s²");
    }
}
