//! Eight strands at once: `verlet` with the direct solver and `ftl`, vectorised across strands.
//!
//! A strand is a chain of dependent square roots and divisions, so one strand at a time is
//! latency-bound; eight strands in the eight f64 lanes of an AVX-512 register (two AVX2 ones)
//! make every operation one vector instruction (two), and the chains of different strands
//! overlap. These methods keep their state in lane form for good (`HairState::Lanes`), so
//! [`StepContext::step_lanes`] steps each chunk in place, with nothing copied in or out.
//!
//! Per lane the arithmetic and its order are the scalar code's (glam's `DVec3` operations:
//! `length` = sqrt of (x² + y²) + z², normalisation multiplies by 1/ℓ), so every compilation
//! ([`super::simd`]) gives the same bits (tested). The collision push and the follow pass's
//! contact case run in lanes, with the scalar code's branches as per-lane selections; only
//! degenerate lanes (a zero-length segment, a parent at the centre, a prediction along the axis,
//! non-finite values) run the scalar code ([`StepContext::follow`]). "Outside the head" is
//! decided on squared distances against an exact threshold ([`sqrt_threshold`]), with no square
//! root. Two things keep LLVM from undoing the vectors (`objdump -d`, `kernel_avx512`): the
//! Newton step's first loop hides its index from the loop vectoriser (which would gather lanes of
//! four segments), and the finite test compares with an opaque `f64::MAX` (a comparison with the
//! constant becomes integer bit tests per lane).

// Lane loops index every array by the lane on purpose: it is the form LLVM turns into one
// vector instruction.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;

use super::direct::{newton_lanes, tension_solve_lanes};
use super::simd::{F8, Isa, LANES, V3, all, any, isa};
use super::{FTL_CORRECTION, HairMethod, HairStats, StepContext};

/// Per-thread storage the kernel needs beside a chunk's state, grown to the strand's size once.
#[derive(Default)]
pub struct LaneScratch {
    /// ftl's start-of-step positions (verlet keeps its own in the state).
    p: Vec<V3>,
    u: Vec<V3>,
    cp: Vec<F8>,
    dp: Vec<F8>,
    /// Predicted positions (verlet), the right-hand side of the tension solve.
    q: Vec<V3>,
    /// Accumulated multipliers (segment tensions) of the Newton steps (verlet).
    mu: Vec<F8>,
}

impl LaneScratch {
    fn fit(&mut self, n: usize) {
        if self.p.len() < n {
            for a in [&mut self.p, &mut self.u, &mut self.q] {
                a.resize(n, V3::default());
            }
            for a in [&mut self.cp, &mut self.dp, &mut self.mu] {
                a.resize(n, F8::ZERO);
            }
        }
    }
}

/// What a chunk measured, per lane.
struct ChunkStats {
    stretch: F8,
    depth2: F8,
    kinetic: F8,
}

/// The measurements of a chunk's new state (as `StepContext::measure`, per lane), taken node by
/// node inside the step's last loop while the node is in registers.
struct Measure {
    l0: F8,
    inv_l0: F8,
    inv_dt: F8,
    center: V3,
    kinetic: F8,
    /// The shortest and longest segments, squared (NaN, which min and max pass over, until a
    /// finite length comes).
    shortest2: F8,
    longest2: F8,
    depth2: F8,
}

impl Measure {
    #[inline(always)]
    fn new(ctx: &StepContext) -> Measure {
        let l0 = ctx.params.segment_length;
        Measure {
            l0: F8::splat(l0),
            inv_l0: F8::splat(1.0 / l0),
            inv_dt: F8::splat(1.0 / ctx.frame_dt),
            center: V3::splat(ctx.center),
            kinetic: F8::ZERO,
            shortest2: F8::splat(f64::NAN),
            longest2: F8::splat(f64::NAN),
            depth2: F8::splat(f64::INFINITY),
        }
    }

    /// Node k's final position (its segment to node k - 1 when k > 0); nodes in order, so the
    /// kinetic energy sums in node order.
    #[inline(always)]
    fn node(&mut self, x: &[V3], p: &[V3], k: usize) {
        let half = F8::splat(0.5);
        let e = half * ((x[k] - p[k]) * self.inv_dt).length_squared();
        if k == 0 {
            // As the separate pass did: the root's term starts the sum.
            self.kinetic = e;
            return;
        }
        let len2 = (x[k] - x[k - 1]).length_squared();
        self.shortest2 = self.shortest2.min(len2);
        self.longest2 = self.longest2.max(len2);
        self.depth2 = self.depth2.min((x[k] - self.center).length_squared());
        self.kinetic = self.kinetic + e;
    }

    #[inline(always)]
    fn finish(self) -> ChunkStats {
        // |ℓ - ℓ0|/ℓ0 as `StepContext::measure` computes it per segment falls and then rises
        // with ℓ² (the square root and every rounding are monotone), so its largest value is at
        // the shortest or the longest segment: two square roots per strand, the same bits.
        let stretch_of = |len2: F8| (len2.sqrt() - self.l0).abs() * self.inv_l0;
        let stretch = F8::ZERO
            .max(stretch_of(self.longest2))
            .max(stretch_of(self.shortest2));
        ChunkStats {
            stretch,
            depth2: self.depth2,
            kinetic: self.kinetic,
        }
    }
}

/// Per-lane inputs computed outside the kernel: the roots' anchors at the end of the step and
/// the acceleration (gravity and the wind at the root).
struct LaneInputs {
    anchor: V3,
    accel: [DVec3; LANES],
}

/// Whether a method keeps its state in lane form and is stepped by
/// [`StepContext::step_lanes`] (verlet with the direct solver, ftl).
pub(super) fn in_lanes(params: &super::HairParams, method: HairMethod) -> bool {
    match method {
        HairMethod::Verlet => params.solver == super::Solver::Direct,
        HairMethod::Ftl => true,
        _ => false,
    }
}

impl StepContext<'_> {
    /// Steps a group of strands in place, [`LANES`] at a time, and measures the result (on the
    /// last inner step). `x` holds the group's chunks in lane form (`nodes` lane vectors per
    /// chunk, see `HairState::Lanes`), `prev` verlet's previous positions, `v` ftl's velocities (the
    /// other one empty).
    pub(super) fn step_lanes(
        &self,
        x: &mut [V3],
        prev: &mut [V3],
        v: &mut [V3],
        roots: &[DVec3],
        s: &mut LaneScratch,
    ) -> HairStats {
        let n = self.params.nodes;
        let ftl = self.method == HairMethod::Ftl;
        s.fit(n);
        let (mut stretch, mut depth2, mut kinetic) = (0.0f64, f64::INFINITY, 0.0f64);
        for (c, x) in x.chunks_exact_mut(n).enumerate() {
            let c0 = c * LANES;
            let live = (roots.len() - c0).min(LANES);
            // The strand of each lane within the chunk (spare lanes repeat the first strand).
            let lane = |l: usize| if l < live { l } else { 0 };
            let inputs = LaneInputs {
                anchor: V3::from_lanes(std::array::from_fn(|l| self.anchor(roots[c0 + lane(l)]))),
                accel: std::array::from_fn(|l| {
                    let root = x[0].lane(lane(l));
                    self.params.gravity + self.wind.at(root)
                }),
            };
            let at = c * n..(c + 1) * n;
            let st = if ftl {
                // ftl keeps no previous positions between steps (its predict sets them).
                let mut p = std::mem::take(&mut s.p);
                let st = self.kernel_dispatch(x, &mut p[..n], &mut v[at], s, &inputs, ftl);
                s.p = p;
                st
            } else {
                self.kernel_dispatch(x, &mut prev[at], &mut [], s, &inputs, ftl)
            };
            if let Some(st) = st {
                for l in 0..live {
                    stretch = stretch.max(st.stretch.0[l]);
                    depth2 = depth2.min(st.depth2.0[l]);
                    kinetic += st.kinetic.0[l];
                }
            }
        }
        if !self.last {
            return HairStats::default();
        }
        HairStats::of_group(stretch, depth2, kinetic, self.collide_radius)
    }

    /// The kernel compiled for the widest vector instructions the processor has (same bits on
    /// every path: module docs).
    fn kernel_dispatch(
        &self,
        x: &mut [V3],
        p: &mut [V3],
        v: &mut [V3],
        s: &mut LaneScratch,
        inputs: &LaneInputs,
        ftl: bool,
    ) -> Option<ChunkStats> {
        match isa() {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the processor has AVX-512F (`isa` checked it).
            Isa::Avx512 => unsafe { self.kernel_avx512(x, p, v, s, inputs, ftl) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the processor has AVX2 (`isa` checked it).
            Isa::Avx2 => unsafe { self.kernel_avx2(x, p, v, s, inputs, ftl) },
            Isa::Portable => self.kernel(x, p, v, s, inputs, ftl),
        }
    }
}

/// [`StepContext::kernel`] compiled with a target feature, under its own name.
macro_rules! kernel_with {
    ($name:ident, $feature:literal) => {
        impl StepContext<'_> {
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = $feature)]
            unsafe fn $name(
                &self,
                x: &mut [V3],
                p: &mut [V3],
                v: &mut [V3],
                s: &mut LaneScratch,
                inputs: &LaneInputs,
                ftl: bool,
            ) -> Option<ChunkStats> {
                self.kernel(x, p, v, s, inputs, ftl)
            }
        }
    };
}
kernel_with!(kernel_avx512, "avx512f");
kernel_with!(kernel_avx2, "avx2");

impl StepContext<'_> {
    /// One step of a chunk of eight strands in place: `x` its positions, `p` the start-of-step
    /// positions (verlet's state, ftl's scratch), `v` ftl's velocities (empty for verlet), one
    /// lane vector per node; their measurements on the last inner step.
    #[inline(always)]
    fn kernel(
        &self,
        x: &mut [V3],
        p: &mut [V3],
        v: &mut [V3],
        s: &mut LaneScratch,
        inputs: &LaneInputs,
        ftl: bool,
    ) -> Option<ChunkStats> {
        let n = x.len();
        let dt = F8::splat(self.dt);
        let keep = F8::splat(self.keep);
        if ftl {
            let adt = V3::from_lanes(inputs.accel.map(|a| a * self.dt));
            for k in 1..n {
                v[k] = (v[k] + adt) * keep;
                p[k] = x[k];
                x[k] = x[k] + v[k] * dt;
            }
            p[0] = x[0];
            x[0] = inputs.anchor;
            // The single pass; v receives each node's length correction d_k.
            for k in 1..n {
                let predicted = x[k];
                let (placed, followed) = self.follow_lanes(x[k - 1], predicted);
                x[k] = placed;
                v[k] = followed - predicted;
            }
            // Velocities from positions, with the DFTL correction -s d_{k+1}/dt.
            let s_corr = F8::splat(FTL_CORRECTION);
            let last = n - 1;
            let mut measure = self.last.then(|| Measure::new(self));
            for k in 0..=last {
                let correction = if k < last && k > 0 {
                    v[k + 1]
                } else {
                    V3::default()
                };
                v[k] = (x[k] - p[k]) / dt - (correction * s_corr) / dt;
                if let Some(m) = measure.as_mut() {
                    m.node(x, p, k);
                }
            }
            measure.map(|m| m.finish())
        } else {
            let adt2 = V3::from_lanes(inputs.accel.map(|a| a * self.dt * self.dt));
            for k in 1..n {
                let next = x[k] + (x[k] - p[k]) * keep + adt2;
                p[k] = x[k];
                x[k] = next;
            }
            p[0] = x[0];
            x[0] = inputs.anchor;
            let l0 = self.params.segment_length;
            let (q, mu) = (&mut s.q[..n], &mut s.mu[..n]);
            q.copy_from_slice(x);
            mu.fill(F8::ZERO);
            let steps = self.params.iterations;
            for i in 0..steps {
                // The last step's positions would be overwritten by the tension solve.
                newton_lanes(
                    x,
                    &mut s.u[..n],
                    &mut s.cp[..n],
                    &mut s.dp[..n],
                    mu,
                    l0,
                    i + 1 < steps,
                    Some(self),
                );
            }
            // With no Newton step (iterations 0, refused by the command line) μ = 0 and this
            // returns the prediction unchanged.
            tension_solve_lanes(x, q, mu, &mut s.cp[..n], l0);
            let mut measure = self.last.then(|| Measure::new(self));
            if let Some(m) = measure.as_mut() {
                m.node(x, p, 0);
            }
            for k in 1..n {
                x[k] = self.follow_lanes(x[k - 1], x[k]).0;
                if let Some(m) = measure.as_mut() {
                    m.node(x, p, k);
                }
            }
            measure.map(|m| m.finish())
        }
    }

    /// [`StepContext::collide`] on eight nodes, in lanes: the lanes inside take the push, the
    /// others keep their node.
    #[inline(always)]
    pub(super) fn collide_lanes(&self, xk: &mut V3) {
        let center = V3::splat(self.center);
        let r = *xk - center;
        let d2 = r.length_squared();
        let rc = self.collide_radius;
        let rc2 = rc * rc;
        let mut inside = [false; LANES];
        for l in 0..LANES {
            inside[l] = (d2.0[l] < rc2) & (d2.0[l] > 0.0);
        }
        if any(inside) {
            let pushed = center + r * (F8::splat(rc) / d2.sqrt());
            *xk = V3::select(inside, pushed, *xk);
        }
    }

    /// [`StepContext::follow`] on eight nodes, in lanes, the degenerate cases by the scalar code
    /// on the lanes that take them (module docs).
    #[inline(always)]
    fn follow_lanes(&self, parent: V3, predicted: V3) -> (V3, V3) {
        let l0 = self.params.segment_length;
        let d = predicted - parent;
        let rcp = F8::splat(1.0) / d.length();
        let dir = d * rcp;
        let candidate = parent + dir * F8::splat(l0);
        let center = V3::splat(self.center);
        // |candidate - centre| >= rc without the square root (`sqrt_threshold`).
        let d2 = (candidate - center).length_squared();
        let outside2 = self.outside2;
        let finite_max = self.finite_max;
        let (mut normal, mut contact) = ([false; LANES], [false; LANES]);
        for l in 0..LANES {
            let r = rcp.0[l];
            // glam's try_normalize: 1/ℓ finite and positive.
            normal[l] = (r > 0.0) & (r <= finite_max);
            // Negated on purpose: NaN takes the contact branch, as in the scalar code.
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            let inside = !(d2.0[l] >= outside2);
            contact[l] = normal[l] & inside;
        }
        if all(normal) && !any(contact) {
            return (candidate, candidate);
        }
        let mut placed = candidate;
        let mut scalar = normal.map(|n| !n);
        if any(contact) {
            let rc = self.collide_radius;
            let axis = center - parent;
            let dist = axis.length();
            let e = axis / dist;
            // Circle of {|y - parent| = l0} ∩ {|y - center| = rc}: centre parent + h e, radius ρ.
            let h = (F8::splat(l0 * l0 - rc * rc) + dist * dist) / (F8::splat(2.0) * dist);
            let rho2 = F8::splat(l0 * l0) - h * h;
            let w = d - e * d.dot(e);
            let w_rcp = F8::splat(1.0) / w.length();
            let on_circle = parent + e * h + (w * w_rcp) * rho2.sqrt();
            let straight_out = parent - e * F8::splat(l0);
            let (mut circle, mut out) = ([false; LANES], [false; LANES]);
            for l in 0..LANES {
                if contact[l] {
                    let wr = w_rcp.0[l];
                    if dist.0[l] == 0.0 {
                        scalar[l] = true;
                    } else if rho2.0[l] < 0.0 {
                        out[l] = true;
                    } else if wr > 0.0 && wr < f64::INFINITY {
                        circle[l] = true;
                    } else {
                        scalar[l] = true;
                    }
                }
            }
            placed = V3::select(circle, on_circle, placed);
            placed = V3::select(out, straight_out, placed);
        }
        let mut followed = candidate;
        for l in 0..LANES {
            if scalar[l] {
                let (a, b) = self.follow(parent.lane(l), predicted.lane(l));
                placed.set_lane(l, a);
                followed.set_lane(l, b);
            }
        }
        (placed, followed)
    }
}

/// The smallest a with fl(√a) ≥ r (r > 0): since the square root is correctly rounded and
/// monotone, `a >= sqrt_threshold(r)` decides `a.sqrt() >= r` exactly, without the root.
pub(super) fn sqrt_threshold(r: f64) -> f64 {
    let mut a = r * r;
    while a > 0.0 && a.next_down().sqrt() >= r {
        a = a.next_down();
    }
    while a.sqrt() < r {
        a = a.next_up();
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::hair::simd::force_isa;
    use crate::scene::hair::{Hair, HairParams};

    /// `a >= sqrt_threshold(r)` decides `a.sqrt() >= r` exactly: checked on the 2000 doubles
    /// around r² for radii of several magnitudes, including the collision radius.
    #[test]
    fn the_square_root_threshold_is_exact() {
        for r in [0.1001, 0.1 * (1.0 + 1e-3), 1.0, 3.0, 1e-7, 12345.678, 0.015] {
            let t = sqrt_threshold(r);
            let mut a = (r * r).next_down();
            for _ in 0..1000 {
                a = a.next_down();
            }
            for _ in 0..2000 {
                assert_eq!(a >= t, a.sqrt() >= r, "r = {r:e}, a = {a:e}, t = {t:e}");
                a = a.next_up();
            }
        }
    }

    /// The stretch the step measures in lanes (shortest and longest segment per strand) is, to
    /// the bit, the largest |ℓ - ℓ0|·(1/ℓ0) over every segment (the formula of
    /// `StepContext::measure`), every frame of a second of the tour, for both lane methods.
    #[test]
    fn the_fused_stretch_equals_the_per_segment_largest() {
        for method in [HairMethod::Verlet, HairMethod::Ftl] {
            let params = HairParams {
                strands: 21,
                ..HairParams::default()
            };
            let (n, l0) = (params.nodes, params.segment_length);
            let mut hair = Hair::new(params, method);
            for _ in 0..60 {
                hair.step(1.0 / 60.0);
                let per_segment = hair
                    .positions()
                    .chunks(n)
                    .flat_map(|x| x.windows(2).map(|w| ((w[1] - w[0]).length() - l0).abs()))
                    .map(|d| d * (1.0 / l0))
                    .fold(0.0, f64::max);
                assert_eq!(
                    hair.stats().max_stretch.to_bits(),
                    per_segment.to_bits(),
                    "{}",
                    method.name()
                );
            }
        }
    }

    /// Every compilation of the kernel this processor runs gives the same bits: positions after
    /// a second of the default tour (hair lying on the head, so the contact branches run) and
    /// the measured invariants, on 21 strands (a partial chunk) for verlet and ftl.
    #[test]
    fn every_kernel_compilation_gives_the_same_bits() {
        let mut paths = vec![Isa::Portable];
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                paths.push(Isa::Avx2);
            }
            if std::arch::is_x86_feature_detected!("avx512f") {
                paths.push(Isa::Avx512);
            }
        }
        let run = |method: HairMethod| {
            let params = HairParams {
                strands: 21,
                ..HairParams::default()
            };
            let mut hair = Hair::new(params, method);
            for _ in 0..60 {
                hair.step(1.0 / 60.0);
            }
            let s = hair.stats();
            (hair.positions().iter())
                .flat_map(|p| p.to_array())
                .chain([s.max_stretch, s.max_penetration, s.kinetic_energy])
                .map(f64::to_bits)
                .collect::<Vec<u64>>()
        };
        for method in [HairMethod::Verlet, HairMethod::Ftl] {
            let results: Vec<Vec<u64>> = paths
                .iter()
                .map(|&isa| {
                    force_isa(Some(isa));
                    let r = run(method);
                    force_isa(None);
                    r
                })
                .collect();
            for (isa, r) in paths.iter().zip(&results) {
                assert!(
                    r == &results[0],
                    "{}: {isa:?} differs from {:?}",
                    method.name(),
                    paths[0]
                );
            }
        }
    }
}
