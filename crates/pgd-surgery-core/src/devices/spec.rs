//! Which device to serve, as the command line names it: `scripted:FILE`, `virtual`,
//! `openhaptics[:NAME]` or `forcedimension`.

use std::path::PathBuf;
use std::str::FromStr;

#[derive(Clone, Debug, PartialEq)]
pub enum DeviceSpec {
    /// Replays a trajectory file.
    Scripted(PathBuf),
    /// Mouse and keyboard in the trainer window.
    Virtual,
    /// A Geomagic device through OpenHaptics: the named one (as the vendor's Touch Setup
    /// names it), or the default.
    OpenHaptics(Option<String>),
    /// The first Force Dimension device (omega, sigma, delta) through its dhd SDK.
    ForceDimension,
}

impl FromStr for DeviceSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.split_once(':') {
            Some(("scripted", path)) if !path.is_empty() => Ok(Self::Scripted(path.into())),
            None if s == "virtual" => Ok(Self::Virtual),
            None if s == "openhaptics" => Ok(Self::OpenHaptics(None)),
            None if s == "forcedimension" => Ok(Self::ForceDimension),
            Some(("openhaptics", name)) if !name.is_empty() => {
                Ok(Self::OpenHaptics(Some(name.into())))
            }
            _ => Err(format!(
                "unknown device `{s}`: expected `scripted:FILE` (a trajectory CSV), `virtual` \
                 (the mouse), `openhaptics[:NAME]` (a Geomagic Touch, Touch X or Phantom) or \
                 `forcedimension` (omega, sigma, delta)"
            )),
        }
    }
}
