//! The trainer's configuration file: what a station of a programme sets once, so that nobody
//! types it at each start (where its attempts are kept, the station's name).
//!
//! Found at the file named by `PGD_TRAINER_CONFIG`, else the first of
//! `$XDG_CONFIG_HOME/pgd-surgery/trainer.ron` (`~/.config/…` without it) and
//! `/etc/pgd-surgery/trainer.ron` that exists; none is needed. Options on the command line win
//! over it.

use std::path::{Path, PathBuf};

use serde::Deserialize;

/// The variable naming the configuration file.
pub const CONFIG_VARIABLE: &str = "PGD_TRAINER_CONFIG";

/// What a configuration file sets; each field may be left out.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainerConfig {
    /// Where attempts are kept: a SQLite file, or a programme's PostgreSQL database as
    /// `postgres://USER[:PASSWORD]@HOST[:PORT]/DATABASE`.
    #[serde(default)]
    pub history: Option<String>,
    /// The station's own SQLite database; with a PostgreSQL history, its copy of the
    /// station's attempts and the queue of those not yet sent.
    #[serde(default)]
    pub local_history: Option<PathBuf>,
    /// This station's name in the shared history (the machine's name without it).
    #[serde(default)]
    pub station: Option<String>,
}

impl TrainerConfig {
    /// The configuration file `path`; an error names the file, the line and column, and the
    /// problem.
    pub fn load(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("{}: cannot be read: {e}", path.display()))?;
        let options = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
        options.from_str(&text).map_err(|e| {
            format!(
                "{}:{}:{}: {} (the trainer's configuration file: docs/programme.md)",
                path.display(),
                e.span.start.line,
                e.span.start.col,
                e.code
            )
        })
    }

    /// The configuration this trainer starts with: the file `PGD_TRAINER_CONFIG` names (which
    /// must exist), else the first of the usual places that exists, else none; with where it
    /// was found.
    pub fn find() -> Result<(Self, Option<PathBuf>), String> {
        if let Some(path) = std::env::var_os(CONFIG_VARIABLE) {
            let path = PathBuf::from(path);
            return Self::load(&path)
                .map(|config| (config, Some(path.clone())))
                .map_err(|e| format!("{e} (named by {CONFIG_VARIABLE})"));
        }
        match usual_places().into_iter().find(|p| p.is_file()) {
            Some(path) => Self::load(&path).map(|config| (config, Some(path))),
            None => Ok((Self::default(), None)),
        }
    }
}

/// Where a configuration file is looked for, in order, when no variable names one.
fn usual_places() -> Vec<PathBuf> {
    let user = std::env::var_os("XDG_CONFIG_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|home| PathBuf::from(home).join(".config")));
    user.map(|folder| folder.join("pgd-surgery/trainer.ron"))
        .into_iter()
        .chain([PathBuf::from("/etc/pgd-surgery/trainer.ron")])
        .collect()
}

/// This machine's name, as the kernel states it: a station's name when none is configured.
pub fn machine_name() -> String {
    ["/proc/sys/kernel/hostname", "/etc/hostname"]
        .iter()
        .find_map(|file| std::fs::read_to_string(file).ok())
        .map(|name| name.trim().to_owned())
        .filter(|name| !name.is_empty())
        .unwrap_or_else(|| "station".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_configuration_is_read_or_refused_where_it_is_wrong() {
        let folder = std::env::temp_dir().join(format!("pgd-config-{}", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        let file = folder.join("trainer.ron");
        std::fs::write(
            &file,
            "(\n  history: \"postgres://station@db/sim\",\n  station: \"lab-1\",\n)\n",
        )
        .unwrap();
        let config = TrainerConfig::load(&file).unwrap();
        assert_eq!(config.history.as_deref(), Some("postgres://station@db/sim"));
        assert_eq!(
            (config.station.as_deref(), config.local_history),
            (Some("lab-1"), None)
        );
        std::fs::write(
            &file,
            "(\n  history: \"h.sqlite\",\n  stations: \"x\",\n)\n",
        )
        .unwrap();
        let error = TrainerConfig::load(&file).unwrap_err();
        assert!(
            error.contains("trainer.ron:3:") && error.contains("stations"),
            "{error}"
        );
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
