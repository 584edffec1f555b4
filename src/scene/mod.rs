//! The physics scenes and the one harness that runs them. Plain Rust over f64 / glam: nothing
//! here knows about Rerun or the command line.

pub mod hair;
pub mod harness;
pub mod m4;
pub mod params;
pub mod pendulum;
pub mod rope;

/// The value named `name` among `choices`, or an error listing the allowed names.
pub fn choice<T: Copy>(name: &str, choices: &[(&'static str, T)]) -> Result<T, String> {
    choices
        .iter()
        .find(|(n, _)| *n == name)
        .map(|&(_, v)| v)
        .ok_or_else(|| {
            let allowed: Vec<&str> = choices.iter().map(|c| c.0).collect();
            format!("'{name}' is not one of {}", allowed.join(", "))
        })
}

/// `FromStr` for the enums chosen by name from a table `ALL` of (name, value), by [`choice`].
macro_rules! from_str_by_choice {
    ($($t:ty),*) => {$(
        impl std::str::FromStr for $t {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                choice(s, &<$t>::ALL)
            }
        }
    )*};
}
from_str_by_choice!(
    hair::Solver,
    hair::HeadMotion,
    rope::run::RopeLayout,
    rope::run::RopePreset
);
