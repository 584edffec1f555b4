//! Work-precision's answer as printed: per target the cheapest run and the scene command that
//! makes it, quoted for a shell.

use super::Error;
use crate::app::SceneFile;
use crate::app::layers::table_of;
use crate::format::shown;
use crate::report::study as report;
use crate::scene::pendulum::run::PendulumConfig;
use crate::scene::rope::run::RopeConfig;
use crate::shell::shell_word;
use crate::study::{Problem, Row, Sweep, answers, scene_command};

/// Keys of a scene's table that the command sets from the run, not from the study's scene.
const RUN_KEYS: &str =
    "dt duration methods fps plot_every window rtol step compensated verlet_damping";

/// The scene's parameters where the study's differ from the scene's defaults, as flags and
/// values as typed (a study's rope is softer and undamped; a scene file may set anything).
pub(super) fn scene_flags(
    problem: &Problem,
    file: &SceneFile,
) -> Result<Vec<(String, String)>, Error> {
    let defaults = match problem {
        Problem::Pendulum(_) => table_of(&PendulumConfig::default())?,
        Problem::Rope(_) => table_of(&RopeConfig::default())?,
    };
    let Some(table) = file.table(problem.name()) else {
        return Ok(Vec::new());
    };
    // The losses as the problem has them: a damped companion's are the scene's, not the file's.
    let mut table = table.clone();
    if let Problem::Rope(p) = problem {
        table.insert("spring_damping".into(), p.spring_damping.into());
        table.insert("air_drag".into(), p.air_drag.into());
    }
    let text = |v: &toml::Value| match v {
        toml::Value::Float(x) => shown(*x),
        toml::Value::String(s) => s.clone(),
        toml::Value::Array(a) => (a.iter().map(|x| x.to_string()))
            .collect::<Vec<_>>()
            .join(","),
        other => other.to_string(),
    };
    Ok((table.iter())
        .filter(|(k, v)| {
            !RUN_KEYS.split(' ').any(|r| r == k.as_str()) && defaults.get(*k) != Some(*v)
        })
        .map(|(k, v)| (k.clone(), text(v)))
        .collect())
}

/// The lines that answer the targets the reference resolves (default ones it cannot are left
/// out, said so), each command quoted for a shell.
pub(super) fn answer(
    problem: &Problem,
    file: &SceneFile,
    sw: &Sweep,
    targets: &[f64],
    rows: &[Row],
    floor: f64,
) -> Result<String, Error> {
    let flags = scene_flags(problem, file)?;
    let scene = (problem.name(), flags.as_slice());
    let schedule = (sw.sample_dt, sw.duration);
    let (mut found, unresolved) = answers(scene, rows, schedule, targets, floor);
    for (_, _, words) in &mut found {
        *words = quoted(words);
    }
    Ok(report::answer(problem, sw, floor, &found, &unresolved))
}

/// Per run, the scene command that makes it, quoted for a shell (its point's hover text).
pub(super) fn commands(
    problem: &Problem,
    file: &SceneFile,
    sw: &Sweep,
    rows: &[Row],
) -> Result<Vec<String>, Error> {
    let flags = scene_flags(problem, file)?;
    let schedule = (sw.sample_dt, sw.duration);
    let command = |r| scene_command(problem.name(), &flags, r, schedule, "run.rrd");
    Ok(rows.iter().map(|r| quoted(&command(r)).join(" ")).collect())
}

fn quoted(words: &[String]) -> Vec<String> {
    (words.iter()).map(|w| shell_word(w.as_bytes())).collect()
}
