//! Bad input is refused before any work: a command line, scene file or recording that would be
//! ignored, is out of any meaningful range or cannot be read ends with exit code 2 and one line
//! naming the flag (or the file and key), the value and what is allowed; no panic, no file written.

#![cfg(feature = "rerun")]

mod common;

use std::sync::atomic::{AtomicUsize, Ordering};

use common::{physlab, s, scratch_dir};
use physlab::scene::params::SceneConfig;

/// Where a row of [`REFUSALS`] writes its recording: [`refuse_all`] puts a scratch path there and
/// checks that nothing appears at it.
const OUT: &str = "<out>";

/// Every refusal that needs no set-up: the command line, the exit code and fragments of the
/// message (a leading `^`: the message starts with it; `!`: the message does not contain it, as
/// values are shown in shortest form). A scene command is given `-o <scratch>` unless the row says
/// where its output goes (`-o`, `--no-record`, `--no-save`, `--print-config`), so that a refusal
/// is seen to write nothing.
const REFUSALS: &[(&[&str], i32, &[&str])] = &[
    // clap: unknown commands and flags, malformed values
    (&["simulate"], 2, &["unrecognized subcommand"]),
    (
        &["pendulum", "--bogus"],
        2,
        &["unexpected argument '--bogus'"],
    ),
    (&["pendulum", "--dt"], 2, &["a value is required for '--dt"]),
    (
        &["pendulum", "--dt", "abc"],
        2,
        &["invalid value 'abc' for '--dt"],
    ),
    (
        &["rope", "--nodes", "2.5"],
        2,
        &["invalid value '2.5' for '--nodes"],
    ),
    (
        &["rope", "--pinned", "a"],
        2,
        &["invalid value 'a' for '--pinned"],
    ),
    (
        &["rope", "--layout", "stacked"],
        2,
        &["invalid value 'stacked' for '--layout"],
    ),
    (
        &["rope", "--preset", "games202"],
        2,
        &["invalid value 'games202' for '--preset"],
    ),
    (
        &["hair", "--head-motion", "spin"],
        2,
        &["invalid value 'spin' for '--head-motion"],
    ),
    (
        &["pendulum", "--dt", "-o", "x.rrd"],
        2,
        &["a value is required for '--dt"],
    ),
    // output options that contradict each other, and viewers
    (
        &["pendulum", "--connect", "ftp://x"],
        2,
        &["not a viewer URL"],
    ),
    (
        &["pendulum", "--no-save", "-o", OUT],
        2,
        &["--no-save with -o"],
    ),
    (&["rope", "--no-save", "-o", OUT], 2, &["--no-save with -o"]),
    (
        &["hair", "--no-record", "-o", OUT],
        2,
        &["--no-record with -o/--output"],
    ),
    (&["hair", "--no-record", "--connect"], 2, &["^error: --no-"]),
    (&["hair", "--no-record", "--spawn"], 2, &["^error: --no-"]),
    (&["hair", "--no-record", "--timings"], 2, &["^error: --no-"]),
    (&["pendulum", "--no-save"], 2, &["^error: --no-"]),
    (
        &["pendulum", "--connect", "not a url", "-o", OUT],
        2,
        &["--connect not a url: not a viewer URL"],
    ),
    // study
    (
        &["study", "convergence", "--nodes", "9"],
        2,
        &["--nodes is a rope parameter"],
    ),
    (
        &["study", "stability", "--stiffness", "10"],
        2,
        &["--stiffness is a rope parameter"],
    ),
    (
        &["study", "convergence", "--scene", "rope", "--theta0", "10"],
        2,
        &["--theta0 is a pendulum parameter"],
    ),
    (
        &["study", "convergence", "--dt", "5"],
        2,
        &["must not exceed --duration / 16"],
    ),
    (
        &["study", "work-precision", "--dt", "1", "--duration", "10"],
        2,
        &["^error: --sample-every 0.32: must be a multiple of --dt 1 s"],
    ),
    // work-precision's targets, horizon in periods and sample interval (issue 39)
    (
        &["study", "work-precision", "--target", "1e-8,0"],
        2,
        &["^error: --target 0: must be a positive error"],
    ),
    (
        &["study", "work-precision", "--target", "NaN"],
        2,
        &["^error: --target NaN: must be a positive error"],
    ),
    (
        &[
            "study",
            "work-precision",
            "--target",
            "1e-15",
            "--repeats",
            "1",
        ],
        2,
        &[
            "^error: --target 1e-15: must be at least 10× the reference's error over this run, \
             2.7e-14 (the floor), so at least 2.7e-13",
        ],
    ),
    (
        &[
            "study",
            "work-precision",
            "--scene",
            "rope",
            "--periods",
            "3",
        ],
        2,
        &["^error: --periods 3: needs a scene with a period"],
    ),
    (
        &["study", "work-precision", "--theta0", "0", "--periods", "3"],
        2,
        &["^error: --periods 3: needs a scene with a period"],
    ),
    (
        &["study", "work-precision", "--periods", "0"],
        2,
        &["^error: --periods 0: must be"],
    ),
    (
        &[
            "study",
            "work-precision",
            "--periods",
            "3",
            "--duration",
            "5",
        ],
        2,
        &["'--periods <N>' cannot be used with '--duration <S>'"],
    ),
    (
        &["study", "work-precision", "--sample-every", "0.33"],
        2,
        &["^error: --sample-every 0.33: must be a multiple of --dt 0.02 s"],
    ),
    (
        &["study", "work-precision", "--sample-every", "20"],
        2,
        &["^error: --sample-every 20: must not exceed --duration 10 s"],
    ),
    (
        &["study", "convergence", "--dt", "1e-9"],
        2,
        &["reference steps; at most 1e9"],
    ),
    (
        &["study", "convergence", "--dt", "1e-4", "--levels", "20"],
        2,
        &["reference steps; at most 1e9"],
    ),
    (
        &["study", "drift", "--theta0", "180"],
        2,
        &["--theta0 180: `study drift` needs a release from rest with |θ0| < 180°"],
    ),
    (
        &["study", "drift", "--theta0", "0"],
        2,
        &["--theta0 0: `study drift` needs a swing to measure"],
    ),
    (
        &["study", "drift", "--theta0", "1e-300"],
        2,
        &[
            "`study drift` needs a swing to measure",
            "energy is 0e0 J/kg",
        ],
    ),
    // A flag of another kind: clap's refusal, with the kinds that take it.
    (
        &["study", "drift", "--omega0", "1"],
        2,
        &[
            "unexpected argument '--omega0'",
            "--omega0 is a flag of `study convergence`, `study work-precision` only",
        ],
    ),
    (
        &[
            "study",
            "drift",
            "--methods",
            "dopri5",
            "--rtol",
            "1e-6,1e-8",
        ],
        2,
        &["`study drift` runs each adaptive method at one tolerance"],
    ),
    (
        &["study", "drift", "--dt", "1e-9", "--duration", "1e6"],
        2,
        &["steps; between 10 per method and 1e10 in all"],
    ),
    (
        &["study", "work-precision", "--rtol", "1e-300"],
        2,
        &["--rtol 1e-300: must be between 1e-14 and 0.1", "!00000000"],
    ),
    (
        &["study", "work-precision", "--rtol", "1e300"],
        2,
        &["--rtol 1e300: must be between 1e-14 and 0.1", "!00000000"],
    ),
    (
        &["study", "work-precision", "--rtol", "5e-15"],
        2,
        &["--rtol 5e-15: must be between 1e-14 and 0.1", "!00000000"],
    ),
    // pendulum
    (
        &["pendulum", "--methods", "rk5"],
        2,
        &["unknown method 'rk5'"],
    ),
    (
        &["pendulum", "--methods", "rk4,euler"],
        2,
        &["unknown method 'euler'"],
    ),
    (
        &["pendulum", "--dt", "0"],
        2,
        &["--dt 0: must be a finite number > 0"],
    ),
    (
        &["pendulum", "--dt", "-0.1"],
        2,
        &["--dt -0.1: must be a finite number > 0"],
    ),
    (
        &["pendulum", "--dt", "inf"],
        2,
        &["--dt inf: must be a finite number > 0"],
    ),
    (
        &["pendulum", "--duration", "0"],
        2,
        &["--duration 0: must be a finite number > 0"],
    ),
    (
        &["pendulum", "--dt", "2", "--duration", "1"],
        2,
        &[
            "--dt 2: must not exceed --duration 1",
            "must not exceed --duration",
        ],
    ),
    (
        &["pendulum", "--dt", "1e-12", "--duration", "100"],
        2,
        &["at most 1e9 are allowed"],
    ),
    (
        &["pendulum", "--fps", "0"],
        2,
        &["--fps 0: must be a finite number > 0"],
    ),
    (
        &["pendulum", "--gravity", "0"],
        2,
        &["--gravity 0: must be between 1e-6 and 1e6 [m/s²]"],
    ),
    (
        &["pendulum", "--length", "-2"],
        2,
        &["--length -2: must be between 1e-6 and 1e6 [m]"],
    ),
    (
        &["pendulum", "--theta0", "nan"],
        2,
        &["--theta0 NaN: must be a finite angle"],
    ),
    (
        &["pendulum", "--omega0", "inf"],
        2,
        &["--omega0 inf: must be between -1e6 and 1e6 [rad/s]"],
    ),
    (
        &["pendulum", "--verlet-damping", "1.5"],
        2,
        &["--verlet-damping 1.5: must be in [0, 1)"],
    ),
    (
        &["pendulum", "--methods", "rkn4", "--step", "0"],
        2,
        &["--step 0: must be a finite number > 0 [s]"],
    ),
    (
        &[
            "pendulum",
            "--methods",
            "rkn4",
            "--step",
            "1e300",
            "--duration",
            "5",
        ],
        2,
        &["--step 1e300: must not exceed --duration 5 s"],
    ),
    (
        &[
            "pendulum",
            "--methods",
            "rkn4",
            "--dt",
            "1",
            "--step",
            "1e-4",
        ],
        2,
        &["--step 0.0001: must be at least --dt / 4096 = 0.000244140625 s"],
    ),
    (
        &[
            "pendulum",
            "--methods",
            "rkn4",
            "--dt",
            "1",
            "--step",
            "0.001",
            "--duration",
            "1e7",
        ],
        2,
        &[
            "--step 0.001 with --duration 1e7 is 1.00e10 steps",
            "(raise --step or shorten --duration)",
        ],
    ),
    (
        &["pendulum", "--window", "5"],
        2,
        &[
            "invalid value '5' for '--window <FROM:TO>'",
            "must be FROM:TO in seconds",
        ],
    ),
    (
        &["rope", "--window", "0:abc"],
        2,
        &["invalid value '0:abc' for '--window <FROM:TO>'"],
    ),
    (
        &["pendulum", "--window", "30:40"],
        2,
        &["--window 30:40: holds no plotted step of the run, which spans 0 to 20 s"],
    ),
    (
        &["hair", "--window", "5:2"],
        2,
        &[
            "--window 5:2: holds no plotted step",
            "FROM must not be after TO",
        ],
    ),
    (
        &["pendulum", "--duration", "1e5", "--window", "0:1e4"],
        2,
        &[
            "--window 0:10000: the windows keep 1000001 plotted steps per lane",
            "at most 100000",
        ],
    ),
    (
        &["pendulum", "--plot-every", "0"],
        2,
        &["--plot-every 0: must be at least 1"],
    ),
    (
        &["pendulum", "--config", "/nonexistent/scene.toml"],
        2,
        &["cannot read it"],
    ),
    (
        &["pendulum", "--length", "-1"],
        2,
        &["--length -1: must be between 1e-6 and 1e6 [m]"],
    ),
    (&["pendulum", "--dt", "1e-12"], 2, &["at most 1e9"]),
    (
        &["pendulum", "--verlet-damping", "1"],
        2,
        &["--verlet-damping 1: must be in [0, 1)"],
    ),
    (
        &["pendulum", "--length", "1e155"],
        2,
        &["--length 1e155: must be between"],
    ),
    (
        &["pendulum", "--length", "1e-300"],
        2,
        &["--length 1e-300: must be between"],
    ),
    (
        &["pendulum", "--gravity", "1e9"],
        2,
        &["--gravity 1e9: must be between"],
    ),
    (
        &["pendulum", "--omega0", "1e300"],
        2,
        &["must be between -1e6 and 1e6"],
    ),
    (&["pendulum", "--omega0=-inf"], 2, &["--omega0 -inf"]),
    (
        &["pendulum", "--dt", "1e-9"],
        2,
        &["--dt 1e-9 with --duration 20"],
    ),
    (
        &["pendulum", "--methods", "dopri5", "--rtol", "1e-300"],
        2,
        &["--rtol 1e-300: must be between 1e-14 and 0.1", "!00000000"],
    ),
    (
        &["pendulum", "--methods", "dopri5", "--rtol", "1e300"],
        2,
        &["--rtol 1e300: must be between 1e-14 and 0.1", "!00000000"],
    ),
    (
        &["pendulum", "--dt", "1e300"],
        2,
        &["--dt 1e300: must not exceed --duration 20 s", "!00000000"],
    ),
    (
        &["hair", "--margin", "1e300"],
        2,
        &["--margin 1e300: must be in [0, 0.5)", "!00000000"],
    ),
    (
        &["rope", "--end", "1e300,0,0"],
        2,
        &["--end 1e300,0,0: every component must be", "!00000000"],
    ),
    (
        &["pendulum", "--methods", "dopri5", "--rtol", "5e-15"],
        2,
        &["--rtol 5e-15: must be between 1e-14 and 0.1", "!00000000"],
    ),
    (
        &["pendulum", "--verlet-damping", "2e300"],
        2,
        &["--verlet-damping 2e300", "!00000000"],
    ),
    // rope
    (
        &["rope", "--nodes", "-3"],
        2,
        &["--nodes -3: must be a whole number ≥ 0"],
    ),
    (&["rope", "--start", "1,2,3,4"], 2, &["expected x,y,z"]),
    (
        &["rope", "--nodes", "1"],
        2,
        &["--nodes 1: must be between 2"],
    ),
    (
        &["rope", "--pinned", "0,16"],
        2,
        &[
            "--pinned 16: node index out of range",
            "--pinned 16: node index out of range; the rope has nodes 0..=15",
        ],
    ),
    (
        &["rope", "--end", "0,0,0"],
        2,
        &["must differ from --start"],
    ),
    (
        &["rope", "--mass", "0"],
        2,
        &["--mass 0: must be between 1e-6 and 1e6 [kg]"],
    ),
    (
        &["rope", "--stiffness", "-1"],
        2,
        &["--stiffness -1: must be between 1e-6 and 1e12 [N/m]"],
    ),
    (
        &["rope", "--spring-damping", "-1"],
        2,
        &["--spring-damping -1: must be between 0 and 1e6 [N·s/m]"],
    ),
    (
        &["rope", "--air-drag", "nan"],
        2,
        &["--air-drag NaN: must be between 0 and 1e6 [N·s/m]"],
    ),
    (
        &["rope", "--newton-iterations", "0"],
        2,
        &["--newton-iterations 0: must be at least 1"],
    ),
    (
        &["rope", "--nodes", "1000000", "--duration", "1000"],
        2,
        &["node-steps per method"],
    ),
    (
        &[
            "rope",
            "--nodes",
            "9000000",
            "--duration",
            "0.01",
            "--methods",
            "explicit-euler,semi-implicit-euler,implicit-euler,midpoint,trapezoid,rk4,verlet,yoshida4,dopri5,dop853,vern9",
        ],
        2,
        &["of memory, more than"],
    ),
    (&["rope", "--gravity", "0,x"], 2, &["expected x,y,z"]),
    (
        &["rope", "--stiffness", "-5"],
        2,
        &["--stiffness -5: must be between 1e-6 and 1e12 [N/m]"],
    ),
    (
        &["rope", "--nodes", "100000", "--duration", "1000000"],
        2,
        &["node-steps per method"],
    ),
    (&["rope", "--end", "1e300,0,0"], 2, &["--end"]),
    (&["rope", "--start", "0,-1e7,0"], 2, &["within ±1e6"]),
    (&["rope", "--gravity", "0,nan,0"], 2, &["expected x,y,z"]),
    (
        &["rope", "--stiffness", "0"],
        2,
        &["--stiffness 0: must be between 1e-6"],
    ),
    (
        &["rope", "--mass", "1e9"],
        2,
        &["--mass 1e9: must be between"],
    ),
    (
        &["rope", "--air-drag", "1e7"],
        2,
        &["--air-drag 1e7: must be between 0"],
    ),
    (&["rope", "--dt", "1e-12"], 2, &["--dt 1e-12"]),
    // The Nyström methods need forces of position alone: the default rope's damping and drag
    // make them depend on velocity.
    (
        &["rope", "--methods", "verlet,dprkn6"],
        2,
        &[
            "--methods dprkn6: dprkn6 needs forces of position alone; the rope's \
              --spring-damping 0.05 and --air-drag 0.01 make them depend on velocity; set both \
              to 0 or pick another method",
        ],
    ),
    (
        &["rope", "--methods", "rkn4", "--spring-damping", "0"],
        2,
        &[
            "--methods rkn4: rkn4 needs forces of position alone; the rope's --air-drag 0.01 makes them depend on velocity; set it to 0",
        ],
    ),
    (
        &[
            "study",
            "convergence",
            "--scene",
            "rope",
            "--spring-damping",
            "4",
            "--air-drag",
            "0.02",
            "--methods",
            "rk4,dprkn12",
        ],
        2,
        &[
            "--methods dprkn12: dprkn12 needs forces of position alone; the rope's --spring-damping 4 and --air-drag 0.02 make them depend on velocity",
        ],
    ),
    // hair
    (
        &["hair", "--methods", "rk4"],
        2,
        &["unknown hair method 'rk4'"],
    ),
    (&["hair", "--wind", "1,nan,0"], 2, &["expected x,y,z"]),
    (
        &["hair", "--strands", "0"],
        2,
        &["--strands 0: must be between 1"],
    ),
    (
        &["hair", "--nodes", "1"],
        2,
        &["--nodes 1: must be between 2"],
    ),
    (
        &["hair", "--segment-length", "0"],
        2,
        &["--segment-length 0: must be between 1e-6 and 1e6"],
    ),
    (
        &["hair", "--head-radius", "-1"],
        2,
        &["--head-radius -1: must be between 1e-6 and 1e6"],
    ),
    (
        &["hair", "--iterations", "0"],
        2,
        &["--iterations 0: must be at least 1"],
    ),
    (
        &["hair", "--substeps", "0"],
        2,
        &["--substeps 0: must be at least 1"],
    ),
    (
        &["hair", "--margin", "0.7"],
        2,
        &["--margin 0.7: must be in [0, 0.5)"],
    ),
    (
        &["hair", "--gust", "-1"],
        2,
        &["--gust -1: must be a finite number ≥ 0"],
    ),
    (
        &["hair", "--rate", "0"],
        2,
        &["--rate 0: must be a finite number > 0"],
    ),
    (
        &["hair", "--threads", "0"],
        2,
        &["--threads 0: must be between 1 and"],
    ),
    (&["hair", "--wind", "a,b"], 2, &["expected x,y,z"]),
    (
        &[
            "hair",
            "--strands",
            "1000000",
            "--nodes",
            "1000",
            "--duration",
            "600",
        ],
        2,
        &["node-updates per method"],
    ),
    (
        &["hair", "--segment-length", "1e9"],
        2,
        &["--segment-length 1e9: must be between"],
    ),
    (
        &["hair", "--segment-length", "1e-9"],
        2,
        &["--segment-length 1e-9"],
    ),
    (&["hair", "--head-radius", "1e9"], 2, &["--head-radius 1e9"]),
    (&["hair", "--wind", "1e7,0,0"], 2, &["--wind 1e7,0,0"]),
    (&["hair", "--wind", "0,0,inf"], 2, &["--wind"]),
    (&["hair", "--gust", "1e6"], 2, &["--gust 1e6"]),
    (
        &["hair", "--gust", "2", "--wind", "5e5,0,0"],
        2,
        &["the gusts reach"],
    ),
    (&["hair", "--gravity", "0,0,-1e9"], 2, &["--gravity"]),
    (&["hair", "--damping", "1e9"], 2, &["--damping 1e9"]),
    (&["hair", "--stiffness", "1e300"], 2, &["--stiffness 1e300"]),
    (
        &[
            "hair",
            "--methods",
            "semi-implicit-euler",
            "--segment-length",
            "1e-5",
        ],
        2,
        &["the springs' default --stiffness here is k/m = 4.552e14"],
    ),
    (
        &["hair", "--spring-damping", "1e300"],
        2,
        &["--spring-damping 1e300"],
    ),
    (
        &["hair", "--rate", "1e-3"],
        2,
        &["--rate 0.001 Hz over --duration 8 s is less than one frame"],
    ),
    (&["hair", "--rate", "1e12"], 2, &["--rate 1e12"]),
    // refusals that are part of a feature's own rules
    (
        &["pendulum", "--gravity", "3,-4", "--print-config"],
        2,
        &["expected g or x,y,z"],
    ),
    (
        &["pendulum", "--gravity", "1,2,3,4", "--print-config"],
        2,
        &["--gravity", "x,y,z"],
    ),
    (
        &["pendulum", "--gravity", "0,0,0", "--print-config"],
        2,
        &["--gravity 0"],
    ),
    (
        &["hair", "--dt", "0.01", "--print-config"],
        2,
        &[
            "--dt 0.01:",
            "1.6666666666666667 substeps",
            "0.016666666666666666 (1 substep)",
            "0.008333333333333333 (2 substeps)",
        ],
    ),
    (
        &["hair", "--dt", "0.05", "--print-config"],
        2,
        &["0.016666666666666666 (1 substep)"],
    ),
    (
        &[
            "hair",
            "--dt",
            "0.008333333333333333",
            "--substeps",
            "3",
            "--print-config",
        ],
        2,
        &[
            "--dt 0.008333333333333333 and --substeps 3 disagree",
            "2 substeps per frame",
        ],
    ),
    (
        &["all", "--methods", "rk4,ftl,nope", "--print-config"],
        2,
        &["--methods rk4,ftl,nope", "'nope'", "dopri5", "ftl"],
    ),
    (
        &["all", "--methods", "rk4", "--print-config"],
        2,
        &["--methods rk4", "hair", "ftl"],
    ),
    (
        &["all", "--methods", "ftl", "--print-config"],
        2,
        &["the pendulum and the rope", "rk4"],
    ),
    (
        &["study", "convergence", "--levels", "1"],
        2,
        &["--levels 1: must be between 2 and 20"],
    ),
    // files
    (&["inspect", "/nonexistent/run.rrd"], 2, &["cannot read it"]),
    (&["pendulum", "-o", "."], 2, &["-o .: is a folder"]),
    (
        &["study", "stability", "--plots", "Cargo.toml"],
        2,
        &["--plots Cargo.toml: is not a folder"],
    ),
    // `all --dt` is every scene's step: hair takes it only as a whole number of substeps.
    (
        &["all", "--dt", "0.005", "--print-config"],
        2,
        &["--dt 0.005", "3 substeps", "4 substeps"],
    ),
];

#[test]
fn every_refusal_exits_with_its_code_and_one_line_naming_the_value() {
    assert!(REFUSALS.len() >= 100);
    refuse_all(REFUSALS.iter().map(|(args, code, fragments)| {
        (
            args.to_vec(),
            *code,
            fragments.iter().map(|f| f.to_string()).collect(),
        )
    }));
}

/// Runs each refusal and checks it: its exit code, every fragment of its message, no panic,
/// nothing on standard output, no recording written, and physlab's own message on one line
/// (clap's parse errors add a pointer to `--help`).
fn refuse_all<'a>(cases: impl IntoIterator<Item = (Vec<&'a str>, i32, Vec<String>)>) {
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    let dir = scratch_dir(&format!(
        "cli-input-{}",
        CALLS.fetch_add(1, Ordering::Relaxed)
    ));
    let out = dir.join("r.rrd");
    for (args, code, fragments) in cases {
        let mut args: Vec<&str> = args
            .iter()
            .map(|a| if *a == OUT { s(&out) } else { a })
            .collect();
        let says_where = ["-o", "--no-record", "--no-save", "--print-config"];
        if ["pendulum", "rope", "hair", "all"].contains(&args[0])
            && !args.iter().any(|a| says_where.contains(a))
        {
            args.extend(["-o", s(&out)]);
        }
        let (got, stdout, stderr) = physlab(&args);
        assert_eq!(got, code, "{args:?}: exit code {got}, stderr:\n{stderr}");
        for fragment in &fragments {
            let holds = if let Some(start) = fragment.strip_prefix('^') {
                stderr.starts_with(start)
            } else if let Some(absent) = fragment.strip_prefix('!') {
                !stderr.contains(absent)
            } else {
                stderr.contains(fragment.as_str())
            };
            assert!(holds, "{args:?}: expected '{fragment}' of:\n{stderr}");
        }
        assert!(stdout.is_empty(), "{args:?} printed {stdout}");
        assert!(
            stderr.trim().lines().count() == 1 || stderr.contains("try '--help'"),
            "{args:?}: {stderr}"
        );
        assert!(!out.exists(), "{args:?} wrote a recording");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs cases refused with exit code 2 and one fragment each, through [`refuse_all`].
fn refused(cases: &[(Vec<&str>, String)]) {
    refuse_all(
        cases
            .iter()
            .map(|(args, message)| (args.clone(), 2, vec![message.clone()])),
    );
}

/// Which study kinds use each flag, written from what each study measures (not read from the
/// code): convergence and work-precision sweep a start over halved steps (and the adaptive
/// methods over tolerances, timing repeats); stability bisects the linearised problem (no start,
/// no damping, no schedule: `--steps` per trial); drift runs each method once from rest over a
/// long schedule (an angle but no ω0, no damping, one step); hair runs the hair scene's defaults
/// over `--duration` and draws its trade diagram. Every flag given to a kind that does not use it
/// is refused by clap, which names it and the kinds that take it.
#[test]
fn every_study_flag_is_used_or_refused_by_kind() {
    const KINDS: [&str; 5] = [
        "convergence",
        "work-precision",
        "stability",
        "hair",
        "drift",
    ];
    let sweep = &["convergence", "work-precision"][..];
    let measured = &["convergence", "work-precision", "stability", "drift"][..];
    let started = &["convergence", "work-precision", "drift"][..];
    // The rope's losses: the sweeps, and the drift study's energy balance.
    let damped = &["convergence", "work-precision", "drift"][..];
    let flags: [(&[&str], &[&str]); 17] = [
        (&["--scene", "rope"], measured),
        (&["--config", "s.toml"], measured),
        (&["--theta0", "10"], started),
        (&["--omega0", "1"], sweep),
        (&["--scene", "rope", "--nodes", "9"], measured),
        (&["--scene", "rope", "--mass", "1"], measured),
        (&["--scene", "rope", "--stiffness", "10"], measured),
        (&["--scene", "rope", "--spring-damping", "1"], damped),
        (&["--scene", "rope", "--air-drag", "1"], damped),
        (
            &["--duration", "5"],
            &["convergence", "work-precision", "hair", "drift"],
        ),
        (&["--dt", "0.01"], started),
        (&["--levels", "3"], sweep),
        (&["--methods", "rk4"], measured),
        (&["--rtol", "1e-6"], started),
        (&["--repeats", "2"], sweep),
        (&["--steps", "100"], &["stability"]),
        (&["--plots", "plots"], &KINDS),
    ];
    let mut cases = Vec::new();
    for (args, users) in flags {
        let flag = *args.iter().rfind(|a| a.starts_with("--")).unwrap();
        for kind in KINDS.iter().filter(|k| !users.contains(k)) {
            // The first flag a kind does not take is the one named (`--scene` for hair).
            let named = if *kind == "hair" { args[0] } else { flag };
            let takers = if named == flag { users } else { measured };
            let takers: Vec<String> = (KINDS.iter().filter(|k| takers.contains(k)))
                .map(|k| format!("`study {k}`"))
                .collect();
            let mut all = vec!["study", kind];
            all.extend_from_slice(args);
            cases.push((all.clone(), format!("unexpected argument '{named}'")));
            cases.push((
                all,
                format!("{named} is a flag of {} only", takers.join(", ")),
            ));
        }
    }
    assert_eq!(
        cases.len(),
        2 * 30,
        "the table covers every flag a kind leaves out"
    );
    refused(&cases);
}

/// A study refuses a scene file with no table for its scene, as the scene commands do: nothing in
/// it would apply, and the study would run on its defaults as if the file had been read.
#[test]
fn a_study_refuses_a_scene_file_without_its_scenes_table() {
    let dir = scratch_dir("cli-input-study-table");
    let file = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let hair = file("hair.toml", "[hair]\nstrands = 10\n");
    let pendulum = file("pendulum.toml", "[pendulum]\ntheta0 = 30.0\n");
    let no_table = |path: &str, scene: &str| {
        format!("--config {path}: has no [{scene}] table, so nothing in it applies to this command")
    };
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec!["study", "convergence", "--config", &hair],
            no_table(&hair, "pendulum"),
        ),
        (
            vec![
                "study",
                "work-precision",
                "--scene",
                "rope",
                "--config",
                &pendulum,
            ],
            no_table(&pendulum, "rope"),
        ),
        (
            vec![
                "study",
                "stability",
                "--scene",
                "rope",
                "--config",
                &pendulum,
            ],
            no_table(&pendulum, "rope"),
        ),
        (
            vec!["study", "drift", "--config", &hair],
            no_table(&hair, "pendulum"),
        ),
        // The scene command's refusal, for comparison: the same words.
        (
            vec!["pendulum", "--config", &hair, "--no-record"],
            no_table(&hair, "pendulum"),
        ),
    ];
    refused(&cases);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Tolerances with no adaptive method to take them, and empty method lists from a flag or a
/// scene file, for the study and for every scene.
#[test]
fn tolerances_without_an_adaptive_method_and_empty_method_lists_are_refused() {
    let dir = scratch_dir("cli-input-methods");
    let file = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let pendulum = file("p.toml", "[pendulum]\nmethods = []\n");
    let rope = file("r.toml", "[rope]\nmethods = []\n");
    let hair = file("h.toml", "[hair]\nmethods = []\n");
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec![
                "study",
                "convergence",
                "--methods",
                "rk4,verlet",
                "--rtol",
                "1e-6",
            ],
            "--rtol: only dopri5,dop853,vern9,dprkn6,dprkn8,dprkn12 read it, and --methods is rk4,verlet; add one of them to --methods or drop --rtol".into(),
        ),
        (
            vec![
                "study",
                "work-precision",
                "--methods",
                "rk4",
                "--rtol",
                "1e-6",
            ],
            "--rtol: only dopri5".into(),
        ),
        (
            vec!["study", "convergence", "--config", &pendulum],
            "[pendulum] methods = []: lists no method".into(),
        ),
        (
            vec!["study", "stability", "--scene", "rope", "--config", &rope],
            "[rope] methods = []: lists no method".into(),
        ),
        (
            vec!["pendulum", "--config", &pendulum, "--no-record"],
            "[pendulum] methods = []: lists no method".into(),
        ),
        (
            vec!["rope", "--config", &rope, "--no-record"],
            "[rope] methods = []: lists no method".into(),
        ),
        (
            vec!["hair", "--config", &hair, "--no-record"],
            "[hair] methods = []: lists no method".into(),
        ),
    ];
    refused(&cases);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Which methods read each method-specific scene flag, written from what each method does (not
/// read from the code): only verlet has a damping factor; only the error-controlled pairs take a
/// tolerance; only implicit Euler solves with Newton; only the compositions (yoshida4 to
/// sofroniou10) sum compensated (`--compensated`, a switch: an empty value below, `true` in a
/// file); only the fixed-step methods take their own step (`--step`); of the hair methods only verlet has a
/// constraint solver with iterations, and only the spring methods have springs. Given without a
/// method that reads it, each flag is refused; with one, the run goes ahead. A scene file's key is
/// not refused (files state every parameter): the same value from a file runs.
#[test]
fn every_scene_flag_a_method_reads_is_refused_without_that_method() {
    let hair_run = ["--strands", "2", "--duration", "0.05"];
    let cases: [(&str, &str, &str, &str, &str); 14] = [
        (
            "pendulum",
            "--verlet-damping",
            "0.1",
            "rk4,dopri5",
            "verlet",
        ),
        ("pendulum", "--rtol", "1e-6", "rk4,verlet", "vern9"),
        ("rope", "--verlet-damping", "0.1", "rk4", "verlet"),
        ("rope", "--rtol", "1e-6", "implicit-euler", "dop853"),
        ("pendulum", "--compensated", "", "rk4,verlet", "yoshida6"),
        ("rope", "--compensated", "", "verlet", "sofroniou10"),
        ("pendulum", "--step", "0.25", "dop853,dprkn12", "rkn4"),
        ("rope", "--step", "0.002", "vern9", "implicit-euler"),
        (
            "rope",
            "--newton-iterations",
            "3",
            "rk4,verlet",
            "implicit-euler",
        ),
        (
            "hair",
            "--solver",
            "gauss-seidel",
            "ftl,semi-implicit-euler",
            "verlet",
        ),
        ("hair", "--iterations", "3", "ftl,implicit-euler", "verlet"),
        (
            "hair",
            "--stiffness",
            "1e9",
            "verlet,ftl",
            "semi-implicit-euler",
        ),
        ("hair", "--stiffness", "1e9", "verlet", "implicit-euler"),
        ("hair", "--spring-damping", "10", "ftl", "implicit-euler"),
    ];
    let dir = scratch_dir("cli-input-method-flags");
    let mut refusals = Vec::new();
    for (scene, flag, value, without, with) in cases {
        let flag_and_value: &[&str] = if value.is_empty() {
            &[flag]
        } else {
            &[flag, value]
        };
        let mut args = vec![scene, "--methods", without];
        args.extend(flag_and_value);
        args.push("--no-record");
        if scene == "hair" {
            args.extend(hair_run);
        }
        refusals.push((args, format!("{flag}: only ")));
        let mut run = vec![scene, "--methods", with];
        run.extend(flag_and_value);
        run.extend(["--no-record", "-q"]);
        run.extend(if scene == "hair" {
            &hair_run[..]
        } else {
            &["--duration", "0.5"][..]
        });
        let (code, _, stderr) = physlab(&run);
        assert_eq!(code, 0, "{run:?}: {stderr}");
        // The same value in a scene file, beside methods that do not read it, runs.
        let key = flag.trim_start_matches("--").replace('-', "_");
        let quoted = if value.is_empty() {
            "true".to_string()
        } else if value.parse::<f64>().is_ok() {
            value.to_string()
        } else {
            format!("\"{value}\"")
        };
        let path = dir.join(format!("{scene}-{key}.toml"));
        std::fs::write(&path, format!("[{scene}]\n{key} = {quoted}\n")).unwrap();
        let mut from_file = vec![
            scene,
            "--methods",
            without,
            "--config",
            path.to_str().unwrap(),
        ];
        from_file.extend(["--no-record", "-q"]);
        from_file.extend(if scene == "hair" {
            &hair_run[..]
        } else {
            &["--duration", "0.5"][..]
        });
        let (code, _, stderr) = physlab(&from_file);
        assert_eq!(code, 0, "{from_file:?}: {stderr}");
    }
    refused(&refusals);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Flags that set only what a recording draws are refused with --no-record, for every scene and
/// for `all`.
#[test]
fn drawing_flags_are_refused_when_nothing_is_recorded() {
    let mut cases = Vec::new();
    for scene in ["pendulum", "rope", "all"] {
        for flag in ["--fps", "--plot-every"] {
            cases.push((
                vec![scene, flag, "3", "--no-record"],
                format!("--no-record with {flag}: {flag} sets what the recording draws"),
            ));
        }
    }
    cases.push((
        vec!["hair", "--fps", "3", "--no-record"],
        "--no-record with --fps".to_string(),
    ));
    for scene in ["pendulum", "rope", "hair"] {
        cases.push((
            vec![scene, "--window", "0:1", "--no-record"],
            "--no-record with --window: --window sets what the recording draws".to_string(),
        ));
    }
    refused(&cases);
}

/// Angles beyond the stated number of turns (or not finite) are refused by their value; within
/// it any angle is accepted and wrapped.
#[test]
fn angles_are_bounded_by_a_stated_number_of_turns() {
    let mut cases = Vec::new();
    // (`-inf` is not a number clap takes after a space: it is given with `=`.)
    for (value, shown) in [
        (&["--theta0", "inf"][..], "inf"),
        (&["--theta0=-inf"], "-inf"),
        (&["--theta0", "nan"], "NaN"),
        (&["--theta0", "1e300"], "1e300"),
        (&["--theta0", "1e20"], "1e20"),
        (&["--theta0", "360001"], "360001"),
        (&["--theta0", "-360000.5"], "-360000.5"),
    ] {
        for command in [&["pendulum"][..], &["study", "convergence"]] {
            let mut all = command.to_vec();
            all.extend_from_slice(value);
            cases.push((
                all,
                format!("--theta0 {shown}: must be a finite angle within ±1000 turns"),
            ));
        }
    }
    refused(&cases);
    for value in ["360000", "-359999.99", "181", "-539"] {
        let (code, stdout, stderr) = physlab(&["pendulum", "--theta0", value, "--print-config"]);
        assert_eq!(code, 0, "{value}: {stderr}");
        let line = stdout.lines().find(|l| l.starts_with("theta0")).unwrap();
        let printed: f64 = line.split('=').nth(1).unwrap().trim().parse().unwrap();
        assert_eq!(printed, value.parse::<f64>().unwrap(), "{line}");
    }
}

/// An argument that is not UTF-8 is refused on one line naming its option, the value as the
/// shell word that gives it, and what the option takes; nothing is written.
#[test]
fn a_non_utf8_argument_names_its_option_and_value() {
    use std::os::unix::ffi::OsStrExt as _;
    let dir = scratch_dir("non-utf8");
    let out = dir.join("out.rrd");
    let bad = std::ffi::OsStr::from_bytes(b"rk4,\xff");
    let joined = std::ffi::OsStr::from_bytes(b"--methods=\xffx");
    for (args, expected) in [
        (
            vec!["--methods".as_ref(), bad],
            "--methods $'rk4,\\xff': not UTF-8 text",
        ),
        (vec![joined], "--methods $'\\xffx': not UTF-8 text"),
    ] {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_physlab"))
            .arg("pendulum")
            .args(args)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(
            stderr.starts_with(&format!("error: {expected}")),
            "{stderr}"
        );
        assert!(stderr.contains("take UTF-8"), "{stderr}");
        assert!(!out.exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Worker threads are bounded by a stated multiple of the cores; counts and indices that cannot
/// be negative say so, naming the flag and the value.
#[test]
fn counts_are_bounded_and_negative_counts_named() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let max = 4 * cores;
    let too_many = (max + 1).to_string();
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec!["hair", "--threads", "0", "--no-record"],
            format!("--threads 0: must be between 1 and {max} (4 × the {cores} cores here)"),
        ),
        (
            vec!["hair", "--threads", &too_many, "--no-record"],
            format!("--threads {too_many}: must be between 1 and {max}"),
        ),
        (
            vec!["hair", "--threads", "100000", "--no-record"],
            "--threads 100000: must be between 1 and".into(),
        ),
        (
            vec!["rope", "--pinned", "-1"],
            "--pinned -1: must be a whole number ≥ 0".into(),
        ),
        (
            vec!["rope", "--pinned", "0,-3"],
            "--pinned -3: must be a whole number ≥ 0".into(),
        ),
        (
            vec!["rope", "--nodes", "-5"],
            "--nodes -5: must be a whole number ≥ 0".into(),
        ),
        (
            vec!["hair", "--threads", "-2"],
            "--threads -2: must be a whole number ≥ 0".into(),
        ),
        (
            vec!["study", "stability", "--steps", "-100"],
            "--steps -100: must be a whole number ≥ 0".into(),
        ),
    ];
    refused(&cases);
    // At the bound the run goes ahead.
    let at_max = max.to_string();
    let (code, _, stderr) = physlab(&[
        "hair",
        "--threads",
        &at_max,
        "--strands",
        "8",
        "--duration",
        "0.1",
        "--no-record",
        "-q",
    ]);
    assert_eq!(code, 0, "{stderr}");
}

#[cfg(feature = "rerun")]
mod commands {
    //! Refusals that need more than a command line (a folder, a PATH without a viewer, a bound on
    //! how long refusing may take, a file that must stay absent), and the hostile values that are
    //! accepted.

    use std::time::{Duration, Instant};

    use crate::common;
    use crate::common::{physlab, scratch_dir};

    #[test]
    fn no_record_writes_nothing() {
        let dir = scratch_dir("hair-norec");
        let out = dir.join("h.rrd");
        let (code, _, stderr) = physlab(&[
            "hair",
            "--strands",
            "10",
            "--duration",
            "0.5",
            "--no-record",
            "-o",
            out.to_str().unwrap(),
        ]);
        // -o names a file that --no-record would not write: a contradiction, refused.
        assert_eq!(code, 2, "{stderr}");
        assert!(stderr.contains("--no-record with -o/--output"), "{stderr}");
        assert!(!out.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn folders_and_unwritable_paths_are_refused_before_simulating() {
        let dir = scratch_dir("bad-outputs");
        let (code, _, err) = physlab(&["pendulum", "-o", dir.to_str().unwrap()]);
        assert_eq!(code, 2);
        assert!(err.contains("is a folder"), "{err}");
        let blocked = dir.join("file");
        std::fs::write(&blocked, b"x").unwrap();
        // A path under a regular file cannot be created.
        let (code, _, err) = physlab(&["pendulum", "-o", blocked.join("r.rrd").to_str().unwrap()]);
        assert_eq!(code, 1);
        assert!(err.contains("cannot create the folder"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A negative value written after its flag with a space is that flag's value, in every form a
    /// number takes (exponent, sign, lists), for every scene (a real flag after an option that
    /// lacks its value is still a flag: a row of [`super::REFUSALS`]).
    #[test]
    fn negative_values_in_any_number_form_are_values() {
        for (args, expect) in [
            (&["pendulum", "--theta0", "-1e-3"][..], "θ0 = -0.001°"),
            (&["pendulum", "--omega0", "-2.5E-1"], "ω0 = -0.25 rad/s"),
            (&["pendulum", "--theta0", "-.5"], "θ0 = -0.5°"),
            (&["hair", "--wind", "-1e1,0,-2"], "wind [-10.0, 0.0, -2.0]"),
        ] {
            let mut all = args.to_vec();
            all.extend(["--duration", "0.1", "--no-record", "-q"]);
            let (code, stdout, stderr) = physlab(&all);
            assert_eq!(code, 0, "{args:?}: {stderr}");
            // The header lines are wrapped to 100 columns: read as one line.
            let words = stdout.split_whitespace().collect::<Vec<_>>().join(" ");
            assert!(
                words.contains(expect),
                "{args:?}: lacks '{expect}':\n{stdout}"
            );
        }
    }

    /// Every phase counts its steps up front: the pendulum's fine-step reference is refused beyond
    /// 1e9 RK4 steps naming --omega0 (1e5, -1e6, 3e4 over 100 s), and the study refuses a sweep
    /// that cannot finish, whatever the flag that makes it so.
    #[test]
    fn every_phase_refuses_what_cannot_finish_naming_the_option() {
        for (args, message) in [
            (&["pendulum", "--omega0", "1e5"][..], "--omega0 100000"),
            (
                &["pendulum", "--omega0=-1e6", "--duration", "1"],
                "--omega0 -1e6",
            ),
            (
                &["pendulum", "--omega0", "30000", "--duration", "100"],
                "--omega0 30000",
            ),
            (
                &[
                    "pendulum",
                    "--omega0",
                    "1",
                    "--theta0",
                    "10",
                    "--gravity",
                    "1e6",
                    "--length",
                    "1e-6",
                    "--duration",
                    "1e3",
                ],
                "fine-step",
            ),
            (&["study", "convergence", "--dt", "1e-9"], "--dt 1e-9"),
            (&["study", "convergence", "--dt", "1e-300"], "--dt 1e-300"),
            (
                &["study", "convergence", "--dt", "1e-7", "--levels", "2"],
                "reference steps",
            ),
            (&["study", "work-precision", "--levels", "20"], "at most"),
            (
                &["study", "convergence", "--dt", "5"],
                "--dt 5: must not exceed --duration / 16",
            ),
            (
                &["study", "convergence", "--dt", "0.7"],
                "--dt 0.7: must not exceed",
            ),
            (&["study", "convergence", "--dt", "1e300"], "--dt 1e300"),
            (
                &[
                    "study",
                    "convergence",
                    "--scene",
                    "rope",
                    "--dt",
                    "1",
                    "--duration",
                    "1e7",
                ],
                "reference steps",
            ),
            (
                &[
                    "study",
                    "convergence",
                    "--scene",
                    "rope",
                    "--levels",
                    "16",
                    "--nodes",
                    "64",
                ],
                "node-steps",
            ),
            (
                &["study", "convergence", "--repeats", "100", "--levels", "16"],
                "--repeats 100",
            ),
            (
                &[
                    "study",
                    "stability",
                    "--scene",
                    "rope",
                    "--steps",
                    "10000000",
                    "--nodes",
                    "32",
                ],
                "--steps 10000000",
            ),
            (
                &[
                    "study",
                    "stability",
                    "--scene",
                    "rope",
                    "--nodes",
                    "2000",
                    "--steps",
                    "1000000",
                ],
                "--nodes 2000",
            ),
        ] {
            let started = Instant::now();
            let (code, _, stderr) = physlab(args);
            assert_eq!(code, 2, "{args:?} was not refused: {stderr}");
            assert!(stderr.contains(message), "{args:?}: {stderr}");
            assert!(
                stderr.contains("at most") || stderr.contains("must"),
                "{args:?}: {stderr}"
            );
            // Refused up front, not after growing: well under the time any of them would run.
            assert!(started.elapsed() < Duration::from_secs(5), "{args:?}");
        }
    }

    /// Hostile values that are accepted: negative numbers in exponent form are values (written
    /// --theta0=-1e-3: clap reads a separate -1e-3 as flags), and the extremes of every scene's
    /// ranges run without a NaN or inf in the summary or the recording. (Those beyond the ranges
    /// are rows of [`super::REFUSALS`].)
    #[test]
    fn hostile_values_that_are_accepted_run_clean() {
        let dir = scratch_dir("edges-hostile");
        let out = dir.join("x.rrd");
        for args in [
            &["pendulum", "--theta0=-1e-3"][..],
            &["pendulum", "--theta0=-1e-30"],
            &["pendulum", "--omega0=-1e-3", "--theta0=-2e2"],
            &[
                "pendulum",
                "--length",
                "1e-6",
                "--gravity",
                "1e6",
                "--dt",
                "1e-6",
                "--duration",
                "1e-3",
            ],
            &[
                "pendulum",
                "--length",
                "1e6",
                "--gravity",
                "1e-6",
                "--duration",
                "100",
            ],
            &["rope", "--end", "1e-9,0,0", "--duration", "0.1"],
            &["rope", "--end=-1e3,0,0", "--duration", "0.1"],
            &[
                "hair",
                "--wind",
                "1e6,0,0",
                "--gust",
                "0",
                "--duration",
                "0.2",
            ],
            &["hair", "--wind=-1e3,0,0", "--duration", "0.2"],
            &[
                "hair",
                "--nodes",
                "2",
                "--segment-length",
                "1e-6",
                "--duration",
                "0.2",
            ],
            &[
                "hair",
                "--head-radius",
                "1e-6",
                "--gravity",
                "0,0,-1e6",
                "--duration",
                "0.2",
            ],
        ] {
            let mut all = args.to_vec();
            all.extend(["-q", "-o", out.to_str().unwrap()]);
            let (code, stdout, stderr) = physlab(&all);
            assert_eq!(code, 0, "{args:?}: {stderr}");
            let lower = stdout.to_lowercase();
            assert!(
                !lower.contains("nan") && !lower.contains("inf "),
                "{args:?}:\n{stdout}"
            );
            let d = common::decode(&out);
            for (entity, rows) in &d.scalars {
                assert!(
                    rows.iter().all(|r| r.1.is_finite()),
                    "{args:?}: a non-finite value in {entity}"
                );
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn spawn_without_a_viewer_on_path_is_refused_before_simulating() {
        let dir = scratch_dir("live");
        let out = dir.join("p.rrd");
        // --spawn without a `rerun` on PATH: a clear error, and nothing simulated or written.
        let result = std::process::Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args(["pendulum", "--spawn", "-o", out.to_str().unwrap()])
            .env("PATH", dir.to_str().unwrap())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&result.stderr);
        assert_eq!(result.status.code(), Some(1), "{err}");
        assert!(
            err.contains("--spawn: no `rerun` executable on PATH"),
            "{err}"
        );
        assert!(!out.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[cfg(feature = "rerun")]
mod files {
    //! Scene files and recordings given as input: not regular files, of unbounded size, of the wrong
    //! kind, with keys that do not apply or values of the wrong type, refused naming the file.

    use std::path::Path;
    use std::process::Command;
    use std::time::Duration;

    use crate::common::{assert_refused, physlab, run_within, s, scratch_dir};

    fn mkfifo(path: &Path) {
        let status = Command::new("mkfifo").arg(path).status().unwrap();
        assert!(status.success(), "mkfifo {}", path.display());
    }

    #[test]
    fn a_scene_file_that_is_not_a_regular_file_of_bounded_size_is_refused_at_once() {
        let dir = scratch_dir("cli-input-files");
        let fifo = dir.join("fifo.toml");
        mkfifo(&fifo);
        let large = dir.join("large.toml");
        // A valid table padded with comments past the cap: refused for its size, not its content.
        let mut text = String::from("[pendulum]\ntheta0 = 30.0\n");
        while text.len() as u64 <= physlab::app::MAX_SCENE_FILE_BYTES {
            text.push_str("# padding padding padding padding padding padding padding padding\n");
        }
        std::fs::write(&large, &text).unwrap();
        let out = dir.join("x.rrd");
        let out = out.to_str().unwrap();
        let cases: [(&[&str], &Path, &str); 6] = [
            (
                &["pendulum", "-o", out],
                &fifo,
                "is a FIFO (named pipe), not a regular file",
            ),
            (
                &["study", "convergence"],
                &fifo,
                "is a FIFO (named pipe), not a regular file",
            ),
            (
                &["rope", "-o", out],
                Path::new("/dev/zero"),
                "is a character device, not a regular file",
            ),
            (
                &["all", "-o", out],
                Path::new("/dev/null"),
                "is a character device, not a regular file",
            ),
            (&["pendulum", "-o", out], &large, "larger than 1 MiB"),
            (&["study", "stability"], &large, "larger than 1 MiB"),
        ];
        for (args, file, message) in cases {
            let mut all = args.to_vec();
            all.extend(["--config", file.to_str().unwrap()]);
            let (code, stderr, took) = run_within(&all, Duration::from_secs(20));
            assert_eq!(code, 2, "{all:?}: {stderr}");
            assert!(
                stderr.contains(&format!("--config {}: {message}", file.display())),
                "{all:?}: {stderr}"
            );
            assert!(!stderr.contains("empty"), "{all:?}: {stderr}");
            assert_eq!(stderr.trim_end().lines().count(), 1, "{all:?}: {stderr}");
            assert!(took < Duration::from_secs(10), "{all:?} took {took:?}");
        }
        assert!(!Path::new(out).exists(), "a refused run wrote nothing");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_empty_method_list_in_a_scene_file_is_refused_like_an_empty_flag() {
        let dir = scratch_dir("cli-input-empty-methods");
        let out = dir.join("x.rrd");
        let out = out.to_str().unwrap();
        // Every table, and the study reading the same file.
        for (command, table) in [
            (&["pendulum", "-o", out][..], "pendulum"),
            (&["rope", "-o", out], "rope"),
            (&["hair", "-o", out], "hair"),
            (&["all", "-o", out], "hair"),
            (&["study", "convergence"], "pendulum"),
            (&["study", "convergence", "--scene", "rope"], "rope"),
        ] {
            let file = dir.join(format!("{table}.toml"));
            std::fs::write(&file, format!("[{table}]\nfps = 30.0\nmethods = []\n")).unwrap();
            let mut args = command.to_vec();
            args.extend(["--config", file.to_str().unwrap()]);
            let (code, stderr, _) = run_within(&args, Duration::from_secs(60));
            assert_eq!(code, 2, "{args:?}: {stderr}");
            assert!(
                stderr.contains(&format!("line 3: [{table}] methods = []: lists no method")),
                "{args:?}: {stderr}"
            );
        }
        // The flag's own refusal, for comparison: the same class of input, the same exit code.
        for scene in ["pendulum", "rope", "hair"] {
            let (code, stderr, _) = run_within(
                &[scene, "-o", out, "--methods", ""],
                Duration::from_secs(60),
            );
            assert_eq!(code, 2, "{scene} --methods '': {stderr}");
        }
        assert!(!Path::new(out).exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_value_of_the_wrong_type_is_reported_at_its_line_with_its_key_and_the_type_expected() {
        let dir = scratch_dir("cli-input-types");
        let out = dir.join("x.rrd");
        let out = out.to_str().unwrap();
        // Keys of flattened flag groups (theta0, nodes, mass) and plain ones, numbers, text, booleans
        // and dates; each on line 3, below a comment, so that line 1 is never right by accident.
        let cases = [
            ("rope", "nodes = 16.5", "expected usize"),
            ("rope", "mass = true", "expected f64"),
            ("rope", "dt = \"fast\"", "expected f64"),
            ("pendulum", "theta0 = \"x\"", "expected f64"),
            ("pendulum", "dt = 1979-05-27", "date"),
            ("pendulum", "omega0 = 1979-05-27T07:32:00Z", "date"),
            ("rope", "nodes = 07:32:00", "date"),
            ("hair", "strands = 2.5", "expected usize"),
            ("hair", "duration = 1979-05-27", "date"),
        ];
        for (table, line, expected) in cases {
            let file = dir.join(format!("{table}.toml"));
            std::fs::write(&file, format!("# a scene file\n[{table}]\n{line}\n")).unwrap();
            let (code, stderr, _) = run_within(
                &[table, "-o", out, "--config", file.to_str().unwrap()],
                Duration::from_secs(60),
            );
            assert_eq!(code, 2, "{line}: {stderr}");
            let key = line.split(" = ").next().unwrap();
            assert!(stderr.contains("line 3"), "{line}: {stderr}");
            assert!(!stderr.contains("line 1,"), "{line}: {stderr}");
            assert!(stderr.contains(key), "{line}: {stderr}");
            assert!(stderr.contains(expected), "{line}: {stderr}");
            if expected == "date" {
                // The type the key takes is named too, not "map".
                assert!(stderr.contains("expected "), "{line}: {stderr}");
                assert!(!stderr.contains("invalid type: map"), "{line}: {stderr}");
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn scene_files_that_do_not_apply_are_refused_and_their_errors_name_the_key() {
        let dir = scratch_dir("edges-config");
        let out = dir.join("x.rrd");
        let pendulum_only = dir.join("p.toml");
        std::fs::write(&pendulum_only, "[pendulum]\ntheta0 = 30.0\n").unwrap();
        for scene in ["rope", "hair"] {
            assert_refused(
                scene,
                &out,
                &["--config", pendulum_only.to_str().unwrap()],
                &format!("has no [{scene}] table"),
            );
        }
        for (table, key, message) in [
            ("rope", "nodes = 1", "[rope] nodes = 1: must be between 2"),
            ("rope", "mass = 0.0", "[rope] mass = 0: must be between"),
            (
                "pendulum",
                "dt = -1.0",
                "[pendulum] dt = -1: must be a finite number > 0",
            ),
            (
                "hair",
                "strands = 0",
                "[hair] strands = 0: must be between 1",
            ),
        ] {
            let file = dir.join(format!("{table}.toml"));
            std::fs::write(&file, format!("[{table}]\n{key}\n")).unwrap();
            assert_refused(table, &out, &["--config", file.to_str().unwrap()], message);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_scene_files_and_recordings_get_clear_errors() {
        let dir = scratch_dir("bad-files");
        let write = |name: &str, bytes: &[u8]| {
            let p = dir.join(name);
            std::fs::write(&p, bytes).unwrap();
            p.to_str().unwrap().to_string()
        };
        let typo = write("typo.toml", b"[pendulum]\ndt = 0.01\ngravty = 9.81\n");
        let (code, _, err) = physlab(&["pendulum", "--config", &typo, "--print-config"]);
        assert_eq!(code, 2);
        assert!(
            err.contains("typo.toml") && err.contains("line 3") && err.contains("gravty"),
            "{err}"
        );
        let (code, _, err) = physlab(&["all", "--config", &write("empty.toml", b"")]);
        assert_eq!(code, 2);
        assert!(err.contains("empty"), "{err}");
        let (code, _, err) = physlab(&[
            "all",
            "--config",
            &dir.join("missing.toml").to_string_lossy(),
        ]);
        assert_eq!(code, 2);
        assert!(
            err.contains("missing.toml") && err.contains("cannot read"),
            "{err}"
        );

        let (code, _, err) = physlab(&["inspect", &write("text.rrd", b"hello, not a recording\n")]);
        assert_eq!(code, 2);
        assert!(err.contains("not a Rerun recording"), "{err}");
        let (code, _, err) = physlab(&["inspect", &write("empty.rrd", b"")]);
        assert_eq!(code, 2);
        assert!(err.contains("empty"), "{err}");

        // A real recording cut in half.
        let good = dir.join("good.rrd");
        let (code, _, _) = physlab(&["pendulum", "--duration", "2", "-o", good.to_str().unwrap()]);
        assert_eq!(code, 0);
        let bytes = std::fs::read(&good).unwrap();
        let (code, out, err) = physlab(&["inspect", &write("cut.rrd", &bytes[..bytes.len() / 2])]);
        assert!(
            code == 2 && err.contains("truncated") || code == 0 && out.contains("no footer"),
            "a truncated file is reported as such: code {code}\n{out}\n{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_input_is_refused_with_exit_2_naming_the_file() {
        let dir = scratch_dir("reproduce-bad");
        let text = dir.join("notes.rrd");
        std::fs::write(&text, "not a recording\n").unwrap();
        let good = dir.join("good.rrd");
        let (code, _, err) = physlab(&["pendulum", "--duration", "2", "-q", "-o", s(&good)]);
        assert_eq!(code, 0, "{err}");
        let bytes = std::fs::read(&good).unwrap();
        let truncated = dir.join("truncated.rrd");
        std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
        // A recording of another application, and a physlab-named one without a configuration.
        let other = dir.join("other.rrd");
        let bare = dir.join("bare.rrd");
        for (app, path) in [("someone_else", &other), ("physlab", &bare)] {
            let rec = rerun::RecordingStreamBuilder::new(app).save(path).unwrap();
            rec.log("x", &rerun::Scalars::single(1.0)).unwrap();
            drop(rec);
        }
        let missing = dir.join("missing.rrd");
        for (path, message) in [
            (&text, "not a Rerun recording"),
            (&truncated, "truncated"),
            (&other, "another application"),
            (&bare, "no physlab configuration"),
            (&missing, "cannot read it"),
            (&dir, "is a folder"),
        ] {
            for args in [vec!["reproduce", s(path)], vec!["diff", s(&good), s(path)]] {
                if args[0] == "diff" && path == &bare {
                    continue; // diff needs no configuration: it compares the data
                }
                let (code, out, err) = physlab(&args);
                assert_eq!(code, 2, "{args:?}: {out}\n{err}");
                assert!(
                    err.contains(s(path)) && err.contains(message),
                    "{args:?}: expected the file and {message:?} in:\n{err}"
                );
                assert!(!err.contains("panicked"), "{err}");
            }
        }
        let (code, _, err) = physlab(&["reproduce", s(&good), "--tolerance", "-1"]);
        assert_eq!(code, 2);
        assert!(err.contains("--tolerance -1"), "{err}");
        // Writing the re-run over the recording it is compared with is refused; the file is kept.
        let (code, _, err) = physlab(&["reproduce", s(&good), "-o", s(&good)]);
        assert_eq!(code, 2);
        assert!(err.contains("is the recording being compared"), "{err}");
        assert_eq!(std::fs::read(&good).unwrap(), bytes);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// Each outcome's exit code and line (`physlab::error::Error`).
mod error_codes {
    use physlab::error::Error;

    #[test]
    fn each_outcome_keeps_its_exit_code_through_anyhow() {
        type Make = fn(String) -> Error;
        let cases: [(Make, u8, &str); 4] = [
            (Error::Usage, 2, "error: m"),
            (Error::Differs, 1, "m"),
            (Error::Diverged, 3, "m"),
            (Error::Interrupted, 130, "m"),
        ];
        for (make, code, line) in cases {
            let through: Error = anyhow::Error::from(make("m".into())).into();
            assert_eq!(
                (through.exit_code(), through.report().as_str()),
                (code, line)
            );
        }
        let io = std::io::Error::other("disk full");
        let runtime: Error = anyhow::Error::from(io).context("writing x").into();
        assert_eq!(runtime.exit_code(), 1);
        assert_eq!(runtime.report(), "error: writing x: disk full");
    }
}

/// The flags and the configuration name the same parameters: every key the configuration
/// writes is a flag (by clap's argument id, as `app` reads the flags given), and every flag is
/// such a key or one of the `optional` ones a configuration writes only when given.
fn same_parameters<A: clap::Args, C: SceneConfig>(scene: &str, optional: &[&str]) {
    let mut flags: Vec<String> = A::augment_args(clap::Command::new("scene"))
        .get_arguments()
        .map(|a| a.get_id().to_string())
        .collect();
    let config = toml::Table::try_from(C::default()).unwrap();
    let mut keys: Vec<String> = config.keys().cloned().collect();
    keys.extend(optional.iter().map(|k| k.to_string()));
    flags.sort();
    keys.sort();
    assert_eq!(flags, keys, "{scene}");
}

#[test]
fn every_flag_is_a_key_of_its_scenes_configuration_and_back() {
    use physlab::cli::{HairArgs, PendulumArgs, RopeArgs};
    use physlab::scene::hair::run::HairConfig;
    use physlab::scene::pendulum::run::PendulumConfig;
    use physlab::scene::rope::run::RopeConfig;
    same_parameters::<PendulumArgs, PendulumConfig>("pendulum", &["compensated", "step"]);
    same_parameters::<RopeArgs, RopeConfig>("rope", &["preset", "compensated", "step"]);
    same_parameters::<HairArgs, HairConfig>("hair", &["stiffness", "dt", "log_strands"]);
}

fn joined(args: &[&str]) -> Vec<String> {
    physlab::cli::join_negative_values(args.iter().map(|a| a.into()))
        .into_iter()
        .map(|a| a.into_string().unwrap())
        .collect()
}

#[test]
fn negative_numbers_after_a_long_option_are_its_value_and_flags_stay_flags() {
    assert_eq!(
        joined(&["p", "pendulum", "--theta0", "-1e-3", "--omega0", "-2.5E+1"]),
        ["p", "pendulum", "--theta0=-1e-3", "--omega0=-2.5E+1"]
    );
    assert_eq!(
        joined(&["p", "hair", "--wind", "-1,0,-3e2", "-q"]),
        ["p", "hair", "--wind=-1,0,-3e2", "-q"]
    );
    // Not numbers: left for clap (a missing value, a flag, stdout, a negative infinity).
    for args in [
        &["p", "pendulum", "--dt", "-o", "x"][..],
        &["p", "pendulum", "-o", "-"],
        &["p", "pendulum", "--dt", "--", "-1"],
        &["p", "pendulum", "--dt", "-inf"],
        &["p", "pendulum", "--dt=-1", "-1"],
    ] {
        assert_eq!(joined(args), args);
    }
}
