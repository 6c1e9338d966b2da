//! Which device to serve, as the command line names it: `scripted:FILE`, `virtual`,
//! `openhaptics[:NAME]` or `forcedimension[:INDEX]`.

use std::path::PathBuf;
use std::str::FromStr;

/// The dhd SDK serves at most this many devices at once.
pub const MAX_FORCE_DIMENSION_DEVICES: u8 = 16;

#[derive(Clone, Debug, PartialEq)]
pub enum DeviceSpec {
    /// Replays a trajectory file.
    Scripted(PathBuf),
    /// Mouse and keyboard in the trainer window.
    Virtual,
    /// A Geomagic device through OpenHaptics: the named one (as the vendor's Touch Setup
    /// names it), or the default.
    OpenHaptics(Option<String>),
    /// A Force Dimension device (omega, sigma, delta) through its dhd SDK: the one at an
    /// index of the SDK's list (0 first), or the first available.
    ForceDimension(Option<u8>),
}

impl FromStr for DeviceSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.split_once(':') {
            Some(("scripted", path)) if !path.is_empty() => Ok(Self::Scripted(path.into())),
            None if s == "virtual" => Ok(Self::Virtual),
            None if s == "openhaptics" => Ok(Self::OpenHaptics(None)),
            None if s == "forcedimension" => Ok(Self::ForceDimension(None)),
            Some(("openhaptics", name)) if !name.is_empty() => {
                Ok(Self::OpenHaptics(Some(name.into())))
            }
            Some(("forcedimension", index)) => match index.parse::<u8>() {
                Ok(index) if index < MAX_FORCE_DIMENSION_DEVICES => {
                    Ok(Self::ForceDimension(Some(index)))
                }
                _ => Err(format!(
                    "`{s}`: a Force Dimension device's index is a whole number from 0 to {}, \
                     its place in the SDK's list of connected devices",
                    MAX_FORCE_DIMENSION_DEVICES - 1
                )),
            },
            _ => Err(format!(
                "unknown device `{s}`: expected `scripted:FILE` (a trajectory CSV), `virtual` \
                 (the mouse), `openhaptics[:NAME]` (a Geomagic Touch, Touch X or Phantom) or \
                 `forcedimension[:INDEX]` (omega, sigma, delta)"
            )),
        }
    }
}
