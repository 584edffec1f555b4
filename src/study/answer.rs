//! The work-precision study's answer: per target error the cheapest run that reaches it, and the
//! scene command that makes that run, measuring its error at the same samples against the same
//! reference.

use super::{Row, cheapest};
use crate::format::shown;
use crate::scene::params::{self, Invalid};

/// The target errors a work-precision study answers for by default.
pub const DEFAULT_TARGETS: [f64; 5] = [1e-3, 1e-6, 1e-8, 1e-10, 1e-12];

/// A target is resolved by the reference when it is at least this many times the reference's
/// error: the reference's own error then moves a run's measured error by a tenth at most.
pub const RESOLVES: f64 = 10.0;

/// The reference's error (the study's floor) as every text and diagram says it.
pub fn floor_text(reference_error: f64) -> String {
    crate::format::sig(reference_error, 2)
}

/// Each target a positive, finite error.
pub fn validate_targets(targets: &[f64]) -> Result<(), Invalid> {
    for &t in targets {
        let ok = t.is_finite() && t > 0.0;
        params::require(ok, "--target", t, "must be a positive error, e.g. 1e-8")?;
    }
    Ok(())
}

/// The targets given refused where the reference cannot resolve them, naming its error (the
/// study's floor).
pub fn refuse_unresolved(targets: &[f64], floor: f64) -> Result<(), Invalid> {
    for &t in targets {
        let rule = format!(
            "must be at least {RESOLVES}× the reference's error over this run, {} (the floor), \
             so at least {}; shorten the run or raise the target",
            floor_text(floor),
            floor_text(RESOLVES * floor)
        );
        params::require(t >= RESOLVES * floor, "--target", t, rule)?;
    }
    Ok(())
}

/// One target's answer: the cheapest run reaching it (median wall time), if one did, and the
/// words (unquoted) of the scene command that makes it.
pub type Answer<'a> = (f64, Option<&'a Row>, Vec<String>);

/// Per target the reference resolves (at least [`RESOLVES`] × `floor`) its [`Answer`], the
/// scene's recording in `recordings/SCENE-TARGET.rrd`; and the targets left out.
pub fn answers<'a>(
    (scene, scene_flags): (&str, &[(String, String)]),
    rows: &'a [Row],
    schedule: (f64, f64),
    targets: &[f64],
    floor: f64,
) -> (Vec<Answer<'a>>, Vec<f64>) {
    let (resolved, unresolved): (Vec<f64>, Vec<f64>) =
        targets.iter().partition(|&&t| t >= RESOLVES * floor);
    let answer = |t: f64| {
        let row = cheapest(rows, t).0;
        let out = format!("recordings/{scene}-{t:e}.rrd");
        let command = |r| scene_command(scene, scene_flags, r, schedule, &out);
        (t, row, row.map_or(Vec::new(), command))
    };
    (resolved.into_iter().map(answer).collect(), unresolved)
}

/// What a run was: the method and every setting that made it, as flags (`--rtol 1e-6`,
/// `--step 0.25 --compensated`). `sample_dt` is the interval it was sampled at.
pub fn settings(row: &Row, sample_dt: f64) -> Vec<String> {
    let mut words = vec!["--methods".to_string(), row.method.name().to_string()];
    match row.rtol {
        Some(rtol) => words.extend(["--rtol".to_string(), shown(rtol)]),
        // A fixed-step method steps at its own step, ending at the samples where it divides
        // their interval, across them otherwise.
        None if row.dt != sample_dt => words.extend(["--step".to_string(), shown(row.dt)]),
        None => {}
    }
    if row.compensated {
        words.push("--compensated".to_string());
    }
    words
}

/// The command (its words, unquoted) that makes `row`'s run as a scene: `physlab SCENE` with the
/// run's [`settings`], --dt at the sample interval (the scene measures its error every dt, so
/// at the study's samples, against the same reference), the study's --duration, the scene's own
/// parameters where they differ from its defaults (`scene_flags`: flag name and value, as
/// typed), and `-o output`.
pub fn scene_command(
    scene: &str,
    scene_flags: &[(String, String)],
    row: &Row,
    (sample_dt, duration): (f64, f64),
    output: &str,
) -> Vec<String> {
    let mut words = vec!["physlab".to_string(), scene.to_string()];
    words.extend(settings(row, sample_dt));
    words.extend(["--dt".to_string(), shown(sample_dt)]);
    words.extend(["--duration".to_string(), shown(duration)]);
    for (flag, value) in scene_flags {
        words.extend([format!("--{}", flag.replace('_', "-")), value.clone()]);
    }
    words.extend(["-o".to_string(), output.to_string()]);
    words
}
