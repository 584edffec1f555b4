//! A study's outputs: checked before any work, reported when written, and what a stopped
//! study says.

use super::Error;
use crate::cli::{StudyKind, StudyOutputs};
use crate::study::Sweep;

/// Prints a complete study's tables `out` and writes what was asked, the recording's
/// provenance the study's scene file and methods.
pub(super) fn write_study(
    a: &StudyOutputs,
    outputs: &Outputs,
    scene: &str,
    (out, csv): (&str, &str),
    diagrams: &[crate::diagram::Diagram],
    (scene_file, methods): (&str, &[&str]),
) -> anyhow::Result<()> {
    // With `-o -` or `--csv -` standard output carries the file: the tables go to stderr.
    let to_stdout = outputs.to_stdout();
    let printed = match a.wide {
        true => out.to_string(),
        false => crate::report::table::fit_lines(out),
    };
    crate::output::print_beside(to_stdout, &printed);
    // Another study writing the same files waits for this set to be whole, and vice versa.
    let _held = crate::output::lock_folders(&outputs.folders())?;
    if let Some(csv_out) = &outputs.csv {
        csv_out.write(csv.as_bytes())?;
        if !csv_out.is_stdout() {
            eprintln!("wrote {}", crate::shell::shown(&csv_out.given));
        }
    }
    if let Some((dir, prefix)) = &outputs.plots {
        for d in diagrams {
            let w = d.write(dir, prefix)?;
            eprintln!(
                "wrote {} and {}",
                crate::shell::shown(&w.svg),
                crate::shell::shown(&w.png)
            );
        }
    }
    if let Some(path) = &a.output {
        let d = crate::record::Destinations::output(path);
        let command = crate::shell::command_line();
        let config = format!("# the scene of `{command}`\n{scene_file}");
        let bytes =
            crate::record::study::record_study(&d, scene, diagrams, out, (&config, methods))?;
        report_recording(path, bytes, to_stdout);
    }
    Ok(())
}

/// Where the study's recording went; on stderr when standard output carries a file.
fn report_recording(path: &std::path::Path, bytes: Option<u64>, to_stdout: bool) {
    let line = match bytes {
        Some(bytes) => format!(
            "\nrecording: {} ({:.2} MB)\n",
            crate::shell::shown(path),
            bytes as f64 / 1e6
        ),
        None => "\nrecording written to standard output\n".into(),
    };
    crate::output::print_beside(to_stdout, &line);
}

/// What a study of `problems` (convergence's damped rope too) says when interrupted.
pub(super) fn interrupted_error(
    kind: &StudyKind,
    problems: &[&crate::study::Problem],
    sw: &Sweep,
    done: usize,
    complete: bool,
) -> anyhow::Error {
    let (planned, what) = match kind {
        StudyKind::Stability(_) => (sw.methods.len(), "methods' limits"),
        StudyKind::Drift(_) => (sw.methods.len(), "runs"),
        _ => (
            problems
                .iter()
                .map(|p| crate::study::planned_runs(p, sw))
                .sum(),
            "runs",
        ),
    };
    interrupted_after(done, planned, what, complete)
}

/// What a stopped study says: `done` of the `planned` `what` complete, and whether they were
/// written.
pub(super) fn interrupted_after(
    done: usize,
    planned: usize,
    what: &str,
    complete: bool,
) -> anyhow::Error {
    let kept = match complete {
        true => "; the tables above (and any --csv and -o files) hold the complete ones",
        false => "; nothing was written",
    };
    let said = format!("interrupted: {done} of {planned} {what} complete{kept}");
    Error::Interrupted(said).into()
}

/// A study's outputs, checked before it runs (`crate::output`): the CSV, the recording, and
/// the diagrams' folder with the prefix of their names (--plots, else beside the recording or
/// the CSV and named after it, so that two studies write one figure only when given one
/// --plots).
pub(super) struct Outputs {
    pub(super) csv: Option<crate::output::Output>,
    pub(super) recording: Option<crate::output::Output>,
    pub(super) plots: Option<(std::path::PathBuf, String)>,
}

impl Outputs {
    fn folders(&self) -> Vec<std::path::PathBuf> {
        let targets = self.files().filter_map(|o| o.target.as_deref());
        let plots = self.plots.as_ref().map(|p| p.0.clone());
        (targets.map(crate::output::parent_dir))
            .chain(plots)
            .collect()
    }

    fn files(&self) -> impl Iterator<Item = &crate::output::Output> {
        [&self.csv, &self.recording].into_iter().flatten()
    }

    pub(super) fn to_stdout(&self) -> bool {
        self.files().any(|o| o.is_stdout())
    }
}

pub(super) fn check_outputs(
    a: &StudyOutputs,
    config: Option<&std::path::Path>,
    stems: &[String],
) -> anyhow::Result<Outputs> {
    use crate::output::{Dash, check, distinct};
    use std::path::Path;
    let csv = (a.csv.as_deref()).map(|p| check("--csv", p, Dash::Text));
    let csv = csv.transpose()?;
    let recording = match &a.output {
        Some(path) => crate::record::Destinations::output(path).written()?,
        None => None,
    };
    let beside = |o: &crate::output::Output| {
        let t = o.target.as_deref()?;
        let stem = t.file_stem().unwrap_or_default().to_string_lossy();
        Some((crate::output::parent_dir(t), format!("{stem}-")))
    };
    if a.plots.as_deref() == Some(Path::new("-")) {
        return Err(Error::Usage(
            "--plots -: standard output is not a folder; --plots names the folder of the diagrams"
                .into(),
        )
        .into());
    }
    let plots = (a.plots.clone().map(|dir| (dir, String::new())))
        .or_else(|| recording.as_ref().and_then(beside))
        .or_else(|| csv.as_ref().and_then(beside))
        .filter(|_| !stems.is_empty());
    let mut diagrams = Vec::new();
    if let Some((dir, prefix)) = &plots {
        if dir.exists() && !dir.is_dir() {
            return Err(Error::Usage(format!(
                "--plots {}: is not a folder; --plots names the folder the diagrams go to",
                dir.display()
            ))
            .into());
        }
        let no_dash = Dash::Refused("is not a folder");
        for stem in stems {
            for file in crate::diagram::Diagram::files(&format!("{prefix}{stem}"), dir) {
                diagrams.push(check("--plots", &file, no_dash)?);
            }
        }
    }
    let all: Vec<&crate::output::Output> =
        (csv.iter().chain(&recording)).chain(&diagrams).collect();
    let read = config.map(|p| ("the scene file read (--config)", p));
    let inputs: Vec<(&str, &Path)> = read.into_iter().collect();
    distinct(&all, &inputs)?;
    Ok(Outputs {
        csv,
        recording,
        plots,
    })
}
