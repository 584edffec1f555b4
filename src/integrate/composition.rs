//! Symmetric compositions of position Verlet: Yoshida's triple jump (order 4) and the
//! higher-order compositions of Yoshida (6), Kahan & Li (8) and Sofroniou & Spaletta (10), one
//! stepper with a weight table each.

use super::{Method, SecondOrderSystem, State};

/// Yoshida's fourth-order composition stays stable on the oscillator for h < 1.5734019...,
/// where the trace of its one-step matrix reaches ±2 (`tests/integrators.rs` finds it again).
pub const YOSHIDA4_STABILITY_LIMIT: f64 = 1.573_401_947_434_54;

/// The first h > 0 at which |trace| of the one-step matrix on x'' = -x exceeds 2, for the
/// higher-order compositions (2.26905799639765941786574525903, 3.09643868000073217261468949411
/// and 3.14108186289662319003496785934 by `tests/data/composition_stability.py`, mpmath at 40
/// digits; `tests/integrators.rs` finds them again from the weights in f64). Past each the
/// trace comes back: unstable on 2.2691–2.3278, 3.0964–3.1402 and 3.14108–3.14184 only, then
/// stable again for a while (gaps of the stability interval).
pub const YOSHIDA6_STABILITY_LIMIT: f64 = 2.269_057_996_397_659_6;
pub const KAHAN_LI8_STABILITY_LIMIT: f64 = 3.096_438_680_000_732;
pub const SOFRONIOU10_STABILITY_LIMIT: f64 = 3.141_081_862_896_623_3;

/// Yoshida's triple-jump weights: w1 = 1/(2 - 2^(1/3)), w0 = -2^(1/3)/(2 - 2^(1/3)).
pub fn yoshida_weights() -> (f64, f64) {
    let c = 2f64.powf(1.0 / 3.0);
    (1.0 / (2.0 - c), -c / (2.0 - c))
}

/// The palindrome of `half` (its last entry the middle one): w1 … wk … w1.
const fn palindrome<const N: usize, const S: usize>(half: [f64; N]) -> [f64; S] {
    assert!(S == 2 * N - 1);
    let mut out = [0.0; S];
    let mut i = 0;
    while i < N {
        out[i] = half[i];
        out[S - 1 - i] = half[i];
        i += 1;
    }
    out
}

/// Yoshida's triple jump, the doubles `yoshida_weights` gives (a test checks them bit for bit).
pub const YOSHIDA4: [f64; 3] = palindrome([1.351_207_191_959_657_8, -1.702_414_383_919_315_3]);

/// Yoshida (1990), "solution A", 7 substeps. Digits as Hairer, Lubich & Wanner (GNI, V.3.11)
/// print them, found identical in two public codes (a Julia composition table and a Python
/// splitting code); the middle weight 1 - 2 (w1 + w2 + w3) computed to 36 digits.
#[allow(clippy::excessive_precision)] // the digits as their sources print them
pub const YOSHIDA6: [f64; 7] = palindrome([
    0.784_513_610_477_557_263_819_497_633_866,
    0.235_573_213_359_358_133_684_793_182_979,
    -1.177_679_984_178_871_006_946_415_680_964,
    1.315_186_320_683_911_218_884_249_728_239,
]);

/// Kahan & Li (1997), s17odr8a, 17 substeps: the eighth-order composition GNI (V.3.14) and
/// DifferentialEquations.jl (`KahanLi8`, symplectic_tableaus.jl) carry, 26 digits, the same in
/// a Fortran guiding-centre code's table "Kahan & Li s = 17, in the form of Hairer".
#[allow(clippy::excessive_precision)] // the digits as their sources print them
pub const KAHAN_LI8: [f64; 17] = palindrome([
    0.130_202_483_088_890_080_878_817_63,
    0.561_162_981_775_108_384_561_964_41,
    -0.389_474_962_644_847_286_408_078_60,
    0.158_841_906_555_155_600_896_210_75,
    -0.395_903_894_133_237_577_336_231_54,
    0.184_539_640_978_315_707_091_832_54,
    0.258_374_387_686_322_047_293_979_11,
    0.295_011_723_609_310_298_870_966_24,
    -0.605_508_533_830_034_511_698_921_08,
]);

/// Sofroniou & Spaletta (2005), s35odr10, 35 substeps: 32 digits from SUNDIALS ARKODE
/// (`ARKodeSymplecticSofroniou10`), agreeing to the 26 that DifferentialEquations.jl
/// (`SofSpa10`) prints.
#[allow(clippy::excessive_precision)] // the digits as their sources print them
pub const SOFRONIOU10: [f64; 35] = palindrome([
    0.078_795_722_521_686_419_263_907_679_337_684,
    0.313_096_103_415_108_527_764_812_471_926_47,
    0.027_918_383_235_078_066_109_520_273_275_299,
    -0.229_592_841_593_907_094_151_213_396_796_55,
    0.130_962_061_077_164_863_174_656_859_279_61,
    -0.269_733_405_654_510_714_344_609_732_224_11,
    0.074_973_343_155_891_435_666_137_105_641_410,
    0.111_993_423_999_810_204_889_575_080_736_40,
    0.366_133_449_546_226_751_193_148_123_531_50,
    -0.399_105_630_136_035_897_878_629_810_583_40,
    0.103_087_398_527_471_077_315_802_770_013_72,
    0.411_430_873_955_890_237_820_704_118_976_08,
    -0.004_866_360_583_135_261_762_195_659_309_977_1,
    -0.392_033_353_708_639_906_448_081_936_426_10,
    0.051_942_502_962_449_647_037_182_904_015_976,
    0.050_665_090_759_924_496_335_874_344_156_866,
    0.049_674_370_639_729_879_054_568_800_279_461,
    0.049_317_735_759_594_537_917_680_008_339_338,
]);

/// The substep weights of a composition method; `None` for the other methods.
pub fn weights(method: Method) -> Option<&'static [f64]> {
    match method {
        Method::Yoshida4 => Some(&YOSHIDA4),
        Method::Yoshida6 => Some(&YOSHIDA6),
        Method::KahanLi8 => Some(&KAHAN_LI8),
        Method::Sofroniou10 => Some(&SOFRONIOU10),
        _ => None,
    }
}

/// The k-th of the s + 1 drift weights of the composition of weights `w` (s = w.len()): half
/// the first, the halves of neighbouring weights summed, half the last.
pub fn drift(w: &[f64], k: usize) -> f64 {
    let last = w.len();
    match k {
        0 => 0.5 * w[0],
        _ if k == last => 0.5 * w[last - 1],
        _ => 0.5 * (w[k - 1] + w[k]),
    }
}

/// x += c dx, or with compensation the same sum carried with its rounding error (Kahan): `err`
/// holds what the last additions lost, which the next one adds back, so that an update loses
/// about eps |c dx| instead of eps |x| (`tests/study.rs` measures the effect).
#[inline]
fn accumulate(x: &mut [f64], err: Option<&mut [f64]>, c: f64, dx: &[f64]) {
    match err {
        None => {
            for i in 0..x.len() {
                x[i] += c * dx[i];
            }
        }
        Some(e) => {
            for i in 0..x.len() {
                let y = c * dx[i] - e[i];
                let t = x[i] + y;
                e[i] = (t - x[i]) - y;
                x[i] = t;
            }
        }
    }
}

/// Position-Verlet (drift-kick-drift) substeps of w_k h for each weight w_k, written as s + 1
/// drifts and s kicks, one force evaluation per kick.
///
/// For forces of x alone a symmetric composition of the symmetric, symplectic Verlet substep is
/// symplectic and of the order its weights solve the conditions for. A velocity-dependent force
/// (damping, drag) needs the velocity at the kick's middle, (v_pre + v_post)/2, for the substep
/// to stay symmetric, which an explicit step cannot have: a kick with the pre-kick velocity costs
/// the whole composition its order (measured 1.0 on the damped oscillator and the damped rope).
/// Each kick therefore evaluates a(x, v_pre + (w h / 2) a_last), the middle velocity predicted
/// with the last acceleration evaluated (of the previous kick; zero before the first): accurate
/// to O(h²), which makes the step second order with velocity-dependent forces, at no extra
/// evaluation. For a(x) the velocity argument is unused and nothing changes.
#[derive(Clone, Debug)]
pub struct Composition {
    weights: &'static [f64],
    /// The last acceleration evaluated; zero before the first kick.
    a: Vec<f64>,
    /// The kick's velocity argument: v predicted at the kick's middle.
    v_mid: Vec<f64>,
    /// With compensated summation, the rounding errors of x and v carried to the next update.
    compensation: Option<(Vec<f64>, Vec<f64>)>,
}

impl Composition {
    pub fn new(n: usize, weights: &'static [f64], compensated: bool) -> Self {
        Composition {
            weights,
            a: vec![0.0; n],
            v_mid: vec![0.0; n],
            compensation: compensated.then(|| (vec![0.0; n], vec![0.0; n])),
        }
    }

    #[inline]
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, h: f64) {
        let n = s.x.len();
        let (x, v) = (s.x, s.v);
        let w = self.weights;
        let last = w.len();
        for k in 0..=last {
            let (ex, ev) = match &mut self.compensation {
                Some((ex, ev)) => (Some(ex.as_mut_slice()), Some(ev.as_mut_slice())),
                None => (None, None),
            };
            accumulate(x, ex, drift(w, k) * h, v);
            if let Some(&kick) = w.get(k) {
                for i in 0..n {
                    self.v_mid[i] = v[i] + 0.5 * kick * h * self.a[i];
                }
                sys.acceleration(x, &self.v_mid, &mut self.a);
                s.counts.evals += 1;
                accumulate(v, ev, kick * h, &self.a);
            }
        }
    }
}
