//! A scene's configuration from its layers: its defaults (or the preset it names) < values
//! that replace defaults for one command (the study's rope) < the scene file's table < the flags
//! given. Each layer is a TOML table whose keys are the configuration's own, so that no list of
//! fields is written anywhere.

use serde::Serialize;

use super::SceneFile;
use super::file::at_line;
use crate::error::Error;
use crate::scene::params::SceneConfig;

/// The values given for one scene, besides its defaults.
pub struct Given<'a> {
    pub scene: &'static str,
    /// Values that replace the scene's defaults for this command, below the file.
    pub defaults: toml::Table,
    pub file: &'a SceneFile,
    pub flags: toml::Table,
    /// Every key the scene takes, for the message that refuses one it does not.
    pub keys: Vec<String>,
}

impl Given<'_> {
    /// The configuration these values give, settled and validated. The file's table is checked
    /// alone first, so that a value it refuses is named as its key there.
    pub fn resolve<C: SceneConfig>(&self) -> Result<C, Error> {
        let from_file = self.file.table(self.scene).cloned().unwrap_or_default();
        if let Some(path) = self.file.path() {
            let in_file =
                |e: Error| e.in_file(path, self.scene, |k| self.file.line_of(self.scene, k));
            self.check_keys::<C>(&from_file)?;
            let alone: C = settled(&[&self.defaults, &from_file]).map_err(in_file)?;
            alone.validate().map_err(in_file)?;
        }
        let config: C = settled(&[&self.defaults, &from_file, &self.flags])?;
        config.validate()?;
        Ok(config)
    }

    /// Refuses a key of the file's table that the configuration does not read back (it would
    /// be ignored), and a value its key does not take, at its line.
    fn check_keys<C: SceneConfig>(&self, table: &toml::Table) -> Result<(), Error> {
        let path = (self.file.path()).map_or(String::new(), |p| p.display().to_string());
        let at = |key: &str| at_line(self.file.line_of(self.scene, key));
        let scene = self.scene;
        for (key, value) in table {
            let alone = toml::Table::from_iter([(key.clone(), value.clone())]);
            let read: C = match merged::<C>(&[&alone]).try_into() {
                Ok(config) => config,
                Err(e) => {
                    let why = refusal::<C>(key, value, &e);
                    return Err(Error::Usage(format!(
                        "--config {path}: {}[{scene}] {key} = {value}: {why}",
                        at(key)
                    )));
                }
            };
            if !table_of(&read)?.contains_key(key) {
                return Err(Error::Usage(format!(
                    "--config {path}: {}unknown key `{key}` in [{scene}]; expected one of {}",
                    at(key),
                    self.keys.join(", ")
                )));
            }
        }
        Ok(())
    }
}

/// Why `value` is refused for `key`. A date reads as a map to serde; read as text its error
/// names the type the key takes.
fn refusal<C: SceneConfig>(key: &str, value: &toml::Value, error: &toml::de::Error) -> String {
    let toml::Value::Datetime(date) = value else {
        return error.message().to_string();
    };
    let as_text =
        toml::Table::from_iter([(key.to_string(), toml::Value::String(date.to_string()))]);
    let why = match toml::Value::Table(as_text).try_into::<C>() {
        Err(e) => format!(" (read as text: {})", e.message()),
        Ok(_) => String::new(),
    };
    format!("a TOML date-time is not a value of {key}{why}")
}

/// The layers' configuration over its defaults, or over the preset the layers name, settled.
fn settled<C: SceneConfig>(layers: &[&toml::Table]) -> Result<C, Error> {
    let given = merged::<C>(layers);
    let read = |below: &C| -> Result<C, Error> {
        let mut table = table_of(below)?;
        table.extend(given.clone());
        toml::Value::Table(table)
            .try_into::<C>()
            .map_err(|e| Error::Usage(e.message().to_string()))
    };
    let first = read(&C::default())?;
    let mut config = match first.preset_base() {
        Some(base) => read(&base)?,
        None => first,
    };
    config.settle(&|key| given.contains_key(key))?;
    Ok(config)
}

/// Later layers' keys over earlier ones', each with the keys that set the same value (a flag's
/// `--dt` over a file's `substeps`).
fn merged<C: SceneConfig>(layers: &[&toml::Table]) -> toml::Table {
    let mut out = toml::Table::new();
    for layer in layers {
        for key in layer.keys() {
            C::same_value(key).iter().for_each(|k| _ = out.remove(*k));
        }
        out.extend((*layer).clone());
    }
    out
}

/// `value` as a table: a configuration as its scene-file table, flags as those given.
pub fn table_of(value: &impl Serialize) -> Result<toml::Table, Error> {
    toml::Table::try_from(value).map_err(|e| Error::Runtime(e.into()))
}
