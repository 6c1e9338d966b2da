//! Which device to serve, as the command line names it: `scripted:FILE` or `virtual`.

use std::path::PathBuf;
use std::str::FromStr;

#[derive(Clone, Debug, PartialEq)]
pub enum DeviceSpec {
    /// Replays a trajectory file.
    Scripted(PathBuf),
    /// Mouse and keyboard in the trainer window.
    Virtual,
}

impl FromStr for DeviceSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.split_once(':') {
            Some(("scripted", path)) if !path.is_empty() => Ok(Self::Scripted(path.into())),
            None if s == "virtual" => Ok(Self::Virtual),
            _ => Err(format!(
                "unknown device `{s}`: expected `scripted:FILE` (a trajectory CSV) or `virtual`; \
                 hardware devices are not supported yet"
            )),
        }
    }
}
