//! The lane vocabulary of the hair kernel: [`F8`], eight f64 lanes (one strand each), its
//! masks [`M8`], [`V3`] (x, y, z as three `F8`), and the choice of the kernel's compilation
//! ([`Isa`]: AVX-512, AVX2 or portable, detected at run time).
//!
//! `F8` is a plain `[f64; 8]` whose operations are per-lane loops marked `#[inline(always)]`;
//! inlined into a function compiled with `avx512f` or `avx2` LLVM turns each into one `zmm`
//! instruction or two `ymm` ones. Rust does not contract a·b + c into a fused multiply-add, so
//! every compilation gives the same bits.

// Lane loops index every array by the lane on purpose: it is the form LLVM turns into one
// vector instruction.
#![allow(clippy::needless_range_loop)]

use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::DVec3;

pub const LANES: usize = 8;

/// Eight f64 lanes, one strand each.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
pub struct F8(pub [f64; LANES]);

/// A per-lane condition.
pub(super) type M8 = [bool; LANES];

macro_rules! lanewise {
    ($trait:ident, $f:ident, $op:tt) => {
        impl $trait for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: F8) -> F8 {
                let mut r = [0.0; LANES];
                for i in 0..LANES {
                    r[i] = self.0[i] $op o.0[i];
                }
                F8(r)
            }
        }
    };
}
lanewise!(Add, add, +);
lanewise!(Sub, sub, -);
lanewise!(Mul, mul, *);
lanewise!(Div, div, /);

impl Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        self.map(|a| -a)
    }
}

impl F8 {
    pub const ZERO: F8 = F8([0.0; LANES]);

    #[inline(always)]
    pub fn splat(v: f64) -> F8 {
        F8([v; LANES])
    }
    #[inline(always)]
    pub(super) fn map(self, f: impl Fn(f64) -> f64) -> F8 {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = f(self.0[i]);
        }
        F8(r)
    }
    #[inline(always)]
    pub(super) fn zip(self, o: F8, f: impl Fn(f64, f64) -> f64) -> F8 {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = f(self.0[i], o.0[i]);
        }
        F8(r)
    }
    #[inline(always)]
    pub(super) fn test(self, o: F8, f: impl Fn(f64, f64) -> bool) -> M8 {
        let mut r = [false; LANES];
        for i in 0..LANES {
            r[i] = f(self.0[i], o.0[i]);
        }
        r
    }
    #[inline(always)]
    pub fn sqrt(self) -> F8 {
        self.map(f64::sqrt)
    }
    #[inline(always)]
    pub fn max(self, o: F8) -> F8 {
        self.zip(o, f64::max)
    }
    #[inline(always)]
    pub fn min(self, o: F8) -> F8 {
        self.zip(o, f64::min)
    }
    #[inline(always)]
    pub fn abs(self) -> F8 {
        self.map(f64::abs)
    }
}

/// Whether any lane holds.
#[inline(always)]
pub(super) fn any(m: M8) -> bool {
    bits(m) != 0
}

/// The lanes' conditions as the bits of an integer (LLVM makes one mask move of it).
#[inline(always)]
pub(super) fn bits(m: M8) -> u32 {
    let mut b = 0;
    for l in 0..LANES {
        b |= (m[l] as u32) << l;
    }
    b
}

/// Whether every lane holds.
#[inline(always)]
pub(super) fn all(m: M8) -> bool {
    bits(m) == (1 << LANES) - 1
}

/// Eight 3-vectors, one per lane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct V3 {
    pub x: F8,
    pub y: F8,
    pub z: F8,
}

/// Component by component: `V3 ∘ V3`, or `V3 ∘ F8` with the lane's scalar (as glam's
/// `DVec3 ∘ f64`).
macro_rules! componentwise {
    ($trait:ident, $f:ident, V3, $op:tt) => {
        impl $trait for V3 {
            type Output = V3;
            #[inline(always)]
            fn $f(self, o: V3) -> V3 {
                V3 { x: self.x $op o.x, y: self.y $op o.y, z: self.z $op o.z }
            }
        }
    };
    ($trait:ident, $f:ident, F8, $op:tt) => {
        impl $trait<F8> for V3 {
            type Output = V3;
            #[inline(always)]
            fn $f(self, s: F8) -> V3 {
                V3 { x: self.x $op s, y: self.y $op s, z: self.z $op s }
            }
        }
    };
}
componentwise!(Add, add, V3, +);
componentwise!(Sub, sub, V3, -);
componentwise!(Mul, mul, F8, *);
componentwise!(Div, div, F8, /);

impl V3 {
    #[inline(always)]
    pub fn splat(v: DVec3) -> V3 {
        V3 {
            x: F8::splat(v.x),
            y: F8::splat(v.y),
            z: F8::splat(v.z),
        }
    }
    #[inline(always)]
    pub fn from_lanes(v: [DVec3; LANES]) -> V3 {
        V3 {
            x: F8(v.map(|v| v.x)),
            y: F8(v.map(|v| v.y)),
            z: F8(v.map(|v| v.z)),
        }
    }
    #[inline(always)]
    pub fn lane(&self, i: usize) -> DVec3 {
        DVec3::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, v: DVec3) {
        self.x.0[i] = v.x;
        self.y.0[i] = v.y;
        self.z.0[i] = v.z;
    }
    /// (x·x + y·y) + z·z, as glam.
    #[inline(always)]
    pub fn dot(self, o: V3) -> F8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline(always)]
    pub fn length_squared(self) -> F8 {
        self.dot(self)
    }
    #[inline(always)]
    pub fn length(self) -> F8 {
        self.dot(self).sqrt()
    }
    /// Per lane: `a` where the condition holds, else `b`.
    #[inline(always)]
    pub(super) fn select(m: M8, a: V3, b: V3) -> V3 {
        let pick = |a: F8, b: F8| {
            let mut r = [0.0; LANES];
            for i in 0..LANES {
                r[i] = if m[i] { a.0[i] } else { b.0[i] };
            }
            F8(r)
        };
        V3 {
            x: pick(a.x, b.x),
            y: pick(a.y, b.y),
            z: pick(a.z, b.z),
        }
    }
}

/// Which compilation of the kernel runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Isa {
    /// 512-bit registers: one instruction per lane operation.
    #[cfg(target_arch = "x86_64")]
    Avx512,
    /// 256-bit registers: two instructions per lane operation.
    #[cfg(target_arch = "x86_64")]
    Avx2,
    /// Whatever the target's baseline gives.
    Portable,
}

/// 0: detect; otherwise 1 + the index of the forced [`Isa`] (tests compare the paths).
static FORCED_ISA: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(0);

/// The widest kernel the processor runs (or the one a test forced).
#[inline]
pub(super) fn isa() -> Isa {
    #[cfg(target_arch = "x86_64")]
    {
        match FORCED_ISA.load(std::sync::atomic::Ordering::Relaxed) {
            1 => return Isa::Avx512,
            2 => return Isa::Avx2,
            3 => return Isa::Portable,
            _ => {}
        }
        if std::arch::is_x86_feature_detected!("avx512f") {
            return Isa::Avx512;
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            return Isa::Avx2;
        }
    }
    Isa::Portable
}

/// Forces the kernel's compilation for the whole process (None: the widest the processor
/// has); the caller makes sure the processor has it.
#[cfg(test)]
pub(super) fn force_isa(isa: Option<Isa>) {
    let code = match isa {
        None => 0,
        #[cfg(target_arch = "x86_64")]
        Some(Isa::Avx512) => 1,
        #[cfg(target_arch = "x86_64")]
        Some(Isa::Avx2) => 2,
        Some(Isa::Portable) => 3,
    };
    FORCED_ISA.store(code, std::sync::atomic::Ordering::Relaxed);
}
