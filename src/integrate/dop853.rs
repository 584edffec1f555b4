//! DOP853: Dormand & Prince's explicit Runge–Kutta 8(5,3) pair with its seventh-order dense
//! output, with error control and sampling by interpolation.
//!
//! Source of the coefficients: E. Hairer's `dop853.f` (version of 2004, the code accompanying
//! Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., §II.10),
//! <http://www.unige.ch/~hairer/prog/nonstiff/dop853.f>, with its 30-digit decimals kept
//! verbatim; the same digits as the `ode_solvers` 0.6.2 crate's `butcher_tableau::dopri853`
//! (compared digit for digit; not compared with `differential-equations` 0.6.1). `tests/adaptive.rs` checks the
//! order conditions of the eighth- and embedded fifth-order weights from these numbers.
//!
//! The error estimate and controller follow dop853.f: err = err5² / sqrt(err5² + 0.01 err3²)
//! (its "stretched" fifth-order estimate), scaled per component by rtol (max(|y|, |y_new|) + 1),
//! RMS over the components; the next step 0.9 err^(-1/8), clamped to [1/3, 6] times the last.
//!
//! Dense output (dop853.f's `contd8`): after an accepted step the three extra stages 13, 14, 15
//! are evaluated only if a sample time falls inside the step; then
//! y(t_old + s h) = r1 + s (r2 + s1 (r3 + s (r4 + s1 (r5 + s (r6 + s1 (r7 + s r8)))))), s1 = 1 - s.

use super::{SecondOrderSystem, State};

#[allow(clippy::excessive_precision)]
/// a[i][j] for stages i = 0..16 (row 12, the stage at the new solution, holds B:
/// dop853.f leaves it zero and evaluates f(y_new) directly, which is the same).
const A: [[f64; 16]; 16] = [
    [0.0; 16],
    [
        5.26001519587677318785587544488e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        1.97250569845378994544595329183e-2,
        5.91751709536136983633785987549e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        2.95875854768068491816892993775e-2,
        0.0,
        8.87627564304205475450678981324e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        2.41365134159266685502369798665e-1,
        0.0,
        -8.84549479328286085344864962717e-1,
        9.24834003261792003115737966543e-1,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        3.7037037037037037037037037037e-2,
        0.0,
        0.0,
        1.70828608729473871279604482173e-1,
        1.25467687566822425016691814123e-1,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        3.7109375e-2,
        0.0,
        0.0,
        1.70252211019544039314978060272e-1,
        6.02165389804559606850219397283e-2,
        -1.7578125e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        3.70920001185047927108779319836e-2,
        0.0,
        0.0,
        1.70383925712239993810214054705e-1,
        1.07262030446373284651809199168e-1,
        -1.53194377486244017527936158236e-2,
        8.27378916381402288758473766002e-3,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        6.24110958716075717114429577812e-1,
        0.0,
        0.0,
        -3.36089262944694129406857109825e0,
        -8.68219346841726006818189891453e-1,
        2.75920996994467083049415600797e1,
        2.01540675504778934086186788979e1,
        -4.34898841810699588477366255144e1,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        4.77662536438264365890433908527e-1,
        0.0,
        0.0,
        -2.48811461997166764192642586468e0,
        -5.90290826836842996371446475743e-1,
        2.12300514481811942347288949897e1,
        1.52792336328824235832596922938e1,
        -3.32882109689848629194453265587e1,
        -2.03312017085086261358222928593e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        -9.3714243008598732571704021658e-1,
        0.0,
        0.0,
        5.18637242884406370830023853209e0,
        1.09143734899672957818500254654e0,
        -8.14978701074692612513997267357e0,
        -1.85200656599969598641566180701e1,
        2.27394870993505042818970056734e1,
        2.49360555267965238987089396762e0,
        -3.0467644718982195003823669022e0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        2.27331014751653820792359768449e0,
        0.0,
        0.0,
        -1.05344954667372501984066689879e1,
        -2.00087205822486249909675718444e0,
        -1.79589318631187989172765950534e1,
        2.79488845294199600508499808837e1,
        -2.85899827713502369474065508674e0,
        -8.87285693353062954433549289258e0,
        1.23605671757943030647266201528e1,
        6.43392746015763530355970484046e-1,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        5.42937341165687622380535766363e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        4.45031289275240888144113950566e0,
        1.89151789931450038304281599044e0,
        -5.8012039600105847814672114227e0,
        3.1116436695781989440891606237e-1,
        -1.52160949662516078556178806805e-1,
        2.01365400804030348374776537501e-1,
        4.47106157277725905176885569043e-2,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        5.61675022830479523392909219681e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        2.53500210216624811088794765333e-1,
        -2.46239037470802489917441475441e-1,
        -1.24191423263816360469010140626e-1,
        1.5329179827876569731206322685e-1,
        8.20105229563468988491666602057e-3,
        7.56789766054569976138603589584e-3,
        -8.298e-3,
        0.0,
        0.0,
        0.0,
    ],
    [
        3.18346481635021405060768473261e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        2.83009096723667755288322961402e-2,
        5.35419883074385676223797384372e-2,
        -5.49237485713909884646569340306e-2,
        0.0,
        0.0,
        -1.08347328697249322858509316994e-4,
        3.82571090835658412954920192323e-4,
        -3.40465008687404560802977114492e-4,
        1.41312443674632500278074618366e-1,
        0.0,
        0.0,
    ],
    [
        -4.28896301583791923408573538692e-1,
        0.0,
        0.0,
        0.0,
        0.0,
        -4.69762141536116384314449447206e0,
        7.68342119606259904184240953878e0,
        4.06898981839711007970213554331e0,
        3.56727187455281109270669543021e-1,
        0.0,
        0.0,
        0.0,
        -1.39902416515901462129418009734e-3,
        2.9475147891527723389556272149e0,
        -9.15095847217987001081870187138e0,
        0.0,
    ],
];
/// Eighth-order weights (stages 0..12): row 12 of `A`, the stage at the new solution.
const B: [f64; 12] = {
    let mut b = [0.0; 12];
    let mut j = 0;
    while j < 12 {
        b[j] = A[12][j];
        j += 1;
    }
    b
};
/// Third-order weights of the second error estimate, on stages 0, 8 and 11.
#[allow(clippy::excessive_precision)]
const BHH: [f64; 3] = [
    0.244094488188976377952755905512e+00,
    0.733846688281611857341361741547e+00,
    0.220588235294117647058823529412e-01,
];
/// Fifth-order error weights: B minus the embedded fifth-order weights.
#[allow(clippy::excessive_precision)]
const E5: [f64; 12] = [
    0.1312004499419488073250102996e-01,
    0.0,
    0.0,
    0.0,
    0.0,
    -0.1225156446376204440720569753e+01,
    -0.4957589496572501915214079952e+00,
    0.1664377182454986536961530415e+01,
    -0.3503288487499736816886487290e+00,
    0.3341791187130174790297318841e+00,
    0.8192320648511571246570742613e-01,
    -0.2235530786388629525884427845e-01,
];
/// Dense output: rcont5..rcont8 = h Σ D[r][j] k_j over all 16 stages.
#[allow(clippy::excessive_precision)]
const D: [[f64; 16]; 4] = [
    [
        -0.84289382761090128651353491142e+01,
        0.0,
        0.0,
        0.0,
        0.0,
        0.56671495351937776962531783590e+00,
        -0.30689499459498916912797304727e+01,
        0.23846676565120698287728149680e+01,
        0.21170345824450282767155149946e+01,
        -0.87139158377797299206789907490e+00,
        0.22404374302607882758541771650e+01,
        0.63157877876946881815570249290e+00,
        -0.88990336451333310820698117400e-01,
        0.18148505520854727256656404962e+02,
        -0.91946323924783554000451984436e+01,
        -0.44360363875948939664310572000e+01,
    ],
    [
        0.10427508642579134603413151009e+02,
        0.0,
        0.0,
        0.0,
        0.0,
        0.24228349177525818288430175319e+03,
        0.16520045171727028198505394887e+03,
        -0.37454675472269020279518312152e+03,
        -0.22113666853125306036270938578e+02,
        0.77334326684722638389603898808e+01,
        -0.30674084731089398182061213626e+02,
        -0.93321305264302278729567221706e+01,
        0.15697238121770843886131091075e+02,
        -0.31139403219565177677282850411e+02,
        -0.93529243588444783865713862664e+01,
        0.35816841486394083752465898540e+02,
    ],
    [
        0.19985053242002433820987653617e+02,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.38703730874935176555105901742e+03,
        -0.18917813819516756882830838328e+03,
        0.52780815920542364900561016686e+03,
        -0.11573902539959630126141871134e+02,
        0.68812326946963000169666922661e+01,
        -0.10006050966910838403183860980e+01,
        0.77771377980534432092869265740e+00,
        -0.27782057523535084065932004339e+01,
        -0.60196695231264120758267380846e+02,
        0.84320405506677161018159903784e+02,
        0.11992291136182789328035130030e+02,
    ],
    [
        -0.25693933462703749003312586129e+02,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.15418974869023643374053993627e+03,
        -0.23152937917604549567536039109e+03,
        0.35763911791061412378285349910e+03,
        0.93405324183624310003907691704e+02,
        -0.37458323136451633156875139351e+02,
        0.10409964950896230045147246184e+03,
        0.29840293426660503123344363579e+02,
        -0.43533456590011143754432175058e+02,
        0.96324553959188282948394950600e+02,
        -0.39177261675615439165231486172e+02,
        -0.14972683625798562581422125276e+03,
    ],
];

/// The stepper: its own internal state (it steps past the sample times) and the dense output
/// of its last accepted step, from which the reported state at a sample time is interpolated.
#[derive(Clone, Debug)]
pub struct Dop853 {
    rtol: f64,
    h_max: f64,
    n2: usize,
    /// The internal state y = (x, v) at the end of the last accepted step, time `t`.
    y: Vec<f64>,
    /// The state at the start of the last accepted step (time `t_old`); a trial y_new while a
    /// step is attempted.
    y_old: Vec<f64>,
    /// 16 stages × 2n: k[s] = f(stage s) = (v, a).
    k: Vec<f64>,
    /// A stage's argument.
    yt: Vec<f64>,
    /// Dense-output coefficients r1..r8 of the last accepted step, 8 × 2n.
    cont: Vec<f64>,
    /// Whether the extra stages and `cont` are built for the last accepted step.
    dense_ready: bool,
    /// Internal time, start of the last accepted step, its size, and the controller's next step.
    t: f64,
    t_old: f64,
    h_last: f64,
    h: f64,
    /// Sample steps asked for so far (the reported time is `samples × dt`).
    samples: u64,
    /// 0: k[0] must be evaluated at y; 1: k[0] holds f(y); 2: f(y) is in k[12] (after an
    /// accepted step, kept there until the dense output no longer needs the old stages).
    fsal: u8,
    last_rejected: bool,
    pub(crate) accepted: u64,
    pub(crate) rejected: u64,
}

impl Dop853 {
    pub fn new(x0: &[f64], v0: &[f64], dt: f64, rtol: f64, h_max: f64) -> Self {
        let n = x0.len();
        let mut y = x0.to_vec();
        y.extend_from_slice(v0);
        Dop853 {
            rtol,
            h_max,
            n2: 2 * n,
            y_old: y.clone(),
            y,
            k: vec![0.0; 16 * 2 * n],
            yt: vec![0.0; 2 * n],
            cont: vec![0.0; 8 * 2 * n],
            dense_ready: false,
            t: 0.0,
            t_old: 0.0,
            h_last: 0.0,
            h: dt.min(h_max),
            samples: 0,
            fsal: 0,
            last_rejected: false,
            accepted: 0,
            rejected: 0,
        }
    }

    /// Size of the last accepted step [s] (0 before the first).
    pub fn last_step(&self) -> f64 {
        self.h_last
    }

    /// k = f(y) = (v, a(x, v)).
    #[inline]
    fn eval<S: SecondOrderSystem>(sys: &S, y: &[f64], k: &mut [f64]) {
        let n = y.len() / 2;
        k[..n].copy_from_slice(&y[n..]);
        sys.acceleration(&y[..n], &y[n..], &mut k[n..]);
    }

    /// k_s = f(base + h Σ_{j<s} A[s][j] k_j).
    #[inline]
    fn stage<S: SecondOrderSystem>(
        sys: &S,
        k: &mut [f64],
        yt: &mut [f64],
        base: &[f64],
        s: usize,
        h: f64,
    ) {
        let n2 = base.len();
        let (done, rest) = k.split_at_mut(s * n2);
        for i in 0..n2 {
            let mut acc = 0.0;
            for j in 0..s {
                acc += A[s][j] * done[j * n2 + i];
            }
            yt[i] = base[i] + h * acc;
        }
        Self::eval(sys, yt, &mut rest[..n2]);
    }

    /// One attempted step of size h from (t, y): `Some(accepted)`, or `None` when the error
    /// estimate is not finite (the state blew up).
    fn attempt<S: SecondOrderSystem>(&mut self, sys: &S, evals: &mut u64, h: f64) -> Option<bool> {
        let n2 = self.n2;
        match self.fsal {
            0 => {
                Self::eval(sys, &self.y, &mut self.k[..n2]);
                *evals += 1;
            }
            2 => self.k.copy_within(12 * n2..13 * n2, 0),
            _ => {}
        }
        self.fsal = 1;
        for s in 1..12 {
            Self::stage(sys, &mut self.k, &mut self.yt, &self.y, s, h);
        }
        *evals += 11;
        let rtol = self.rtol;
        let (mut err5, mut err3) = (0.0, 0.0);
        let ynew = &mut self.y_old;
        for i in 0..n2 {
            let (mut b, mut e) = (0.0, 0.0);
            for j in 0..12 {
                let kj = self.k[j * n2 + i];
                b += B[j] * kj;
                e += E5[j] * kj;
            }
            ynew[i] = self.y[i] + h * b;
            let e3 =
                b - BHH[0] * self.k[i] - BHH[1] * self.k[8 * n2 + i] - BHH[2] * self.k[11 * n2 + i];
            let sk = rtol * (self.y[i].abs().max(ynew[i].abs()) + 1.0);
            err5 += (e / sk) * (e / sk);
            err3 += (e3 / sk) * (e3 / sk);
        }
        let mut deno = err5 + 0.01 * err3;
        if deno <= 0.0 {
            deno = 1.0;
        }
        let err = h.abs() * err5 * (1.0 / (n2 as f64 * deno)).sqrt();
        if !err.is_finite() {
            return None;
        }
        let factor = if err == 0.0 {
            6.0
        } else {
            (0.9 * err.powf(-0.125)).clamp(1.0 / 3.0, 6.0)
        };
        if err <= 1.0 {
            // k_12 = f(y_new): the dense output's last stage and the next step's first.
            Self::eval(sys, &self.y_old, &mut self.k[12 * n2..13 * n2]);
            *evals += 1;
            std::mem::swap(&mut self.y, &mut self.y_old);
            self.fsal = 2;
            self.t_old = self.t;
            self.t += h;
            self.h_last = h;
            self.dense_ready = false;
            self.accepted += 1;
            // As dop853.f: no growth right after a rejection.
            self.h = h * if self.last_rejected {
                factor.min(1.0)
            } else {
                factor
            };
            self.last_rejected = false;
            Some(true)
        } else {
            self.rejected += 1;
            self.last_rejected = true;
            self.h = h * factor.min(1.0);
            Some(false)
        }
    }

    /// The extra stages 13-15 and r1..r8 for the last accepted step (dop853.f, after label
    /// "stiffness detection" / `IOUT >= 2`).
    fn build_dense<S: SecondOrderSystem>(&mut self, sys: &S, evals: &mut u64) {
        let n2 = self.n2;
        let h = self.h_last;
        for s in 13..16 {
            Self::stage(sys, &mut self.k, &mut self.yt, &self.y_old, s, h);
        }
        *evals += 3;
        let (k, c) = (&self.k, &mut self.cont);
        for i in 0..n2 {
            let ydiff = self.y[i] - self.y_old[i];
            let bspl = h * k[i] - ydiff;
            c[i] = self.y_old[i];
            c[n2 + i] = ydiff;
            c[2 * n2 + i] = bspl;
            c[3 * n2 + i] = ydiff - h * k[12 * n2 + i] - bspl;
            for r in 0..4 {
                let mut acc = 0.0;
                for j in 0..16 {
                    acc += D[r][j] * k[j * n2 + i];
                }
                c[(4 + r) * n2 + i] = h * acc;
            }
        }
        self.dense_ready = true;
    }

    /// Advances the reported state (x, v) by dt: steps on until the internal time passes the
    /// next sample time, then interpolates there.
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, dt: f64) {
        self.samples += 1;
        let target = self.samples as f64 * dt;
        let n = self.n2 / 2;
        while self.t < target {
            let floor = 1e-14 * target.max(dt);
            let accepted = if self.h.abs() < floor {
                None
            } else {
                self.attempt(sys, &mut s.counts.evals, self.h.min(self.h_max))
            };
            if accepted.is_none() {
                // Leave a non-finite state so the run reports the divergence.
                self.y.fill(f64::NAN);
                s.x.fill(f64::NAN);
                s.v.fill(f64::NAN);
                self.t = f64::INFINITY;
                return;
            }
        }
        if !self.y[0].is_finite() {
            s.x.fill(f64::NAN);
            s.v.fill(f64::NAN);
            return;
        }
        if self.t == target {
            s.x.copy_from_slice(&self.y[..n]);
            s.v.copy_from_slice(&self.y[n..]);
            return;
        }
        if !self.dense_ready {
            self.build_dense(sys, &mut s.counts.evals);
        }
        let th = (target - self.t_old) / self.h_last;
        let th1 = 1.0 - th;
        let n2 = self.n2;
        let c = &self.cont;
        for i in 0..n2 {
            let r = |q: usize| c[q * n2 + i];
            let conpar = r(4) + th * (r(5) + th1 * (r(6) + th * r(7)));
            let value = r(0) + th * (r(1) + th1 * (r(2) + th * (r(3) + th1 * conpar)));
            if i < n {
                s.x[i] = value;
            } else {
                s.v[i - n] = value;
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tableau {
    //! The tableau for the order-condition checks in `integrate::order_conditions`.
    pub const STAGES: usize = 12;
    pub fn a(i: usize, j: usize) -> f64 {
        super::A[i][j]
    }
    pub fn b(j: usize) -> f64 {
        super::B[j]
    }
    pub fn b_embedded(j: usize) -> f64 {
        super::B[j] - super::E5[j]
    }
}
