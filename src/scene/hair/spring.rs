//! Force-based strands: every segment a stiff Hooke spring with damping along it, as the rope
//! models it (`scene::rope`), per unit node mass: F = [k(ℓ - ℓ0) + kd Δv·u] u on the segment's
//! first node, the opposite on its second; plus gravity, the wind and the damping c. The root is
//! held on the moving head (its velocity is the anchor's over the step). Collision pushes a
//! node out to R(1 + margin) and removes the velocity into the head.
//!
//! - symplectic Euler: v += h a(x, v), x += h v, with h within the stability limit of the
//!   highest mode ([`super::HairParams::spring_step_limit`]);
//! - backward Euler: the rope's block-tridiagonal Newton solve, shared through
//!   [`crate::scene::rope::implicit::Chain`], one strand at a time. Three things make it hold
//!   length: Newton to tolerance rather than the linearised
//!   step (a segment turns by O(1) rad in a 60 Hz frame, far outside the linearisation); a
//!   backtracking line search on the incremental potential ([`Chain::merit`]), without which
//!   Newton from the start of the step overshoots; and the head
//!   contact as a penalty inside the solve ([`Chain::node_stiffness`]): pushed out only after
//!   the solve, a node the solve had left deep inside moved alone and crushed its segment to
//!   3% of its length.

use glam::{DMat3, DVec3};

use super::StepContext;
use crate::scene::rope::implicit::{Chain, ChainConstants, Workspace, backward_euler_step};
use crate::scene::rope::node;

/// Per-thread storage for the implicit solve, made for the strand's size once.
#[derive(Default)]
pub struct SpringScratch {
    ws: Option<(usize, Workspace)>,
    x: Vec<f64>,
    v: Vec<f64>,
}

/// One strand as the rope's implicit solve sees it: unit masses, the root pinned.
struct Strand {
    c: ChainConstants,
    /// Gravity plus wind [m/s²].
    accel: DVec3,
    /// The head's centre and the collision radius R(1 + margin): a node inside feels the
    /// contact force k (rc - |x - c|) n inside the solve (a penalty at the springs' stiffness),
    /// so the solve and the collision no longer fight; the push-out after the solve then moves
    /// nodes by the penalty's small depth only.
    center: DVec3,
    collide_radius: f64,
}

impl Strand {
    /// Depth and outward normal of non-root node i inside the collision sphere.
    #[inline]
    fn contact(&self, x: &[f64], i: usize) -> Option<(f64, DVec3)> {
        if i == 0 {
            return None;
        }
        let r = node(x, i) - self.center;
        let d = r.length();
        (d < self.collide_radius && d > 0.0).then(|| (self.collide_radius - d, r / d))
    }
}

impl Chain for Strand {
    #[inline]
    fn constants(&self) -> ChainConstants {
        self.c
    }
    #[inline]
    fn is_pinned(&self, i: usize) -> bool {
        i == 0
    }
    fn definite_jacobian(&self) -> bool {
        true
    }
    fn merit(&self, x: &[f64], v: &[f64], v0: &[f64], h: f64) -> Option<f64> {
        let mut e = 0.0;
        for i in 1..self.c.nodes {
            let (xi, vi) = (node(x, i), node(v, i));
            e += 0.5 * (vi - node(v0, i)).length_squared() - self.accel.dot(xi)
                + h * 0.5 * self.c.air_drag * vi.length_squared();
            if let Some((depth, _)) = self.contact(x, i) {
                e += 0.5 * self.c.stiffness * depth * depth;
            }
        }
        for i in 0..self.c.nodes - 1 {
            let d = node(x, i + 1) - node(x, i);
            let len = d.length();
            e += 0.5 * self.c.stiffness * (len - self.c.rest) * (len - self.c.rest);
            if len > 0.0 {
                let dv = (node(v, i + 1) - node(v, i)).dot(d / len);
                e += h * 0.5 * self.c.spring_damping * dv * dv;
            }
        }
        Some(e)
    }
    fn node_stiffness(&self, x: &[f64], i: usize) -> Option<DMat3> {
        self.contact(x, i).map(|(_, n)| {
            let c = |a: f64| n * (self.c.stiffness * a);
            DMat3::from_cols(c(n.x), c(n.y), c(n.z))
        })
    }
    fn forces(&self, x: &[f64], v: &[f64], f: &mut [f64]) {
        let mut carried = DVec3::ZERO;
        for i in 0..self.c.nodes {
            let mut fi = self.accel - self.c.air_drag * node(v, i) - carried;
            if i + 1 < self.c.nodes {
                let fs = spring_force(
                    node(x, i),
                    node(x, i + 1),
                    node(v, i),
                    node(v, i + 1),
                    self.c.rest,
                    self.c.stiffness,
                    self.c.spring_damping,
                );
                fi += fs;
                carried = fs;
            }
            if let Some((depth, normal)) = self.contact(x, i) {
                fi += self.c.stiffness * depth * normal;
            }
            f[3 * i] = fi.x;
            f[3 * i + 1] = fi.y;
            f[3 * i + 2] = fi.z;
        }
    }
}

/// The spring's force on its first node (the second feels the opposite).
#[inline]
fn spring_force(xa: DVec3, xb: DVec3, va: DVec3, vb: DVec3, rest: f64, k: f64, kd: f64) -> DVec3 {
    let d = xb - xa;
    let len = d.length();
    if len == 0.0 {
        return DVec3::ZERO;
    }
    let u = d / len;
    (k * (len - rest) + kd * (vb - va).dot(u)) * u
}

impl StepContext<'_> {
    /// Pushes a node out of the collision sphere and removes its velocity into the head.
    #[inline]
    fn collide_with_velocity(&self, x: &mut DVec3, v: &mut DVec3) {
        let r = *x - self.center;
        let d2 = r.length_squared();
        let rc = self.collide_radius;
        if d2 < rc * rc && d2 > 0.0 {
            let normal = r / d2.sqrt();
            *x = self.center + normal * rc;
            let vn = v.dot(normal);
            if vn < 0.0 {
                *v -= normal * vn;
            }
        }
    }

    /// One symplectic Euler step of a strand (forces at the start of the step, streamed
    /// segment by segment: node k's update uses the springs on both sides at the old state).
    pub(super) fn spring_symplectic(&self, x: &mut [DVec3], v: &mut [DVec3], root_dir: DVec3) {
        let p = self.params;
        let h = self.dt;
        let a = p.gravity + p.wind_at(self.time, x[0]);
        let (k, kd, l0) = (p.stiffness, p.spring_damping, p.segment_length);
        let n = x.len();
        // The root moves to its anchor at the end of the step, at the anchor's mean velocity.
        let anchor = self.anchor(root_dir);
        let v_root = (anchor - x[0]) / h;
        // Force of the segment above the current node, from the old state.
        let mut above = spring_force(x[0], x[1], v[0], v[1], l0, k, kd);
        x[0] = anchor;
        v[0] = v_root;
        for i in 1..n {
            let below = if i + 1 < n {
                spring_force(x[i], x[i + 1], v[i], v[i + 1], l0, k, kd)
            } else {
                DVec3::ZERO
            };
            let f = a - above + below;
            let mut vi = (v[i] + f * h) * self.keep;
            let mut xi = x[i] + vi * h;
            self.collide_with_velocity(&mut xi, &mut vi);
            x[i] = xi;
            v[i] = vi;
            above = below;
        }
    }

    /// One backward-Euler step of a strand by the rope's solve.
    pub(super) fn spring_implicit(
        &self,
        x: &mut [DVec3],
        v: &mut [DVec3],
        root_dir: DVec3,
        s: &mut SpringScratch,
    ) {
        let p = self.params;
        let h = self.dt;
        let n = x.len();
        let strand = Strand {
            c: ChainConstants {
                nodes: n,
                mass: 1.0,
                stiffness: p.stiffness,
                // With the spring damping's full x-Jacobian (non-symmetric, kd/ℓ cross terms,
                // h kd ≫ 1 at 60 Hz) the step diverged within 0.3 s on every test scene; the
                // strand asks for the definite Jacobian, which leaves that term out
                // ([`Chain::definite_jacobian`]).
                spring_damping: p.spring_damping,
                rest: p.segment_length,
                air_drag: p.damping,
                newton_iterations: super::IMPLICIT_NEWTON_CAP,
            },
            accel: p.gravity + p.wind_at(self.time, x[0]),
            center: self.center,
            collide_radius: self.collide_radius,
        };
        let anchor = self.anchor(root_dir);
        // The root is held (δv = 0) at the velocity that takes it to its anchor.
        v[0] = (anchor - x[0]) / h;
        if !matches!(&s.ws, Some((m, _)) if *m == n) {
            s.ws = Some((n, Workspace::new(n)));
            s.x.resize(3 * n, 0.0);
            s.v.resize(3 * n, 0.0);
        }
        let (xf, vf) = (&mut s.x[..3 * n], &mut s.v[..3 * n]);
        for i in 0..n {
            xf[3 * i..3 * i + 3].copy_from_slice(&x[i].to_array());
            vf[3 * i..3 * i + 3].copy_from_slice(&v[i].to_array());
        }
        let ws = &mut s.ws.as_mut().expect("made above").1;
        backward_euler_step(&strand, ws, xf, vf, h);
        x[0] = anchor;
        for i in 1..n {
            let mut xi = DVec3::new(xf[3 * i], xf[3 * i + 1], xf[3 * i + 2]);
            let mut vi = DVec3::new(vf[3 * i], vf[3 * i + 1], vf[3 * i + 2]);
            self.collide_with_velocity(&mut xi, &mut vi);
            x[i] = xi;
            v[i] = vi;
        }
    }
}
