//! Which device to serve, as the command line names it: `scripted:FILE`, `virtual`,
//! `openhaptics[:NAME]`, `forcedimension[:INDEX]` or `haply[:URL][@ID]`.

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
    /// A Haply Inverse3 through the Haply Inverse Service: the service at a `ws://` URL (or
    /// its default address), the Inverse3 of a device id (or the first listed).
    Haply {
        url: Option<String>,
        device_id: Option<String>,
    },
}

/// `haply[:URL][@ID]` without its `haply`: the URL and the device id, each if given.
fn haply(s: &str, rest: &str) -> Result<DeviceSpec, String> {
    let (url, device_id) = match rest.rsplit_once('@') {
        Some((url, id)) if !id.is_empty() && !id.contains('/') => (url, Some(id.to_owned())),
        Some(_) => {
            return Err(format!(
                "`{s}`: `@` is followed by the Inverse3's device id"
            ));
        }
        None => (rest, None),
    };
    let url = match url.strip_prefix(':') {
        Some(url) if url.starts_with("ws://") => Some(url.to_owned()),
        Some(url) => {
            return Err(format!(
                "`{s}`: `{url}` is not the service's address, ws://HOST:PORT (by default \
                 ws://localhost:10001)"
            ));
        }
        None if url.is_empty() => None,
        None => {
            return Err(format!(
                "`{s}`: expected haply[:ws://HOST:PORT][@DEVICE_ID]"
            ));
        }
    };
    Ok(DeviceSpec::Haply { url, device_id })
}

impl FromStr for DeviceSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if let Some(rest) = s.strip_prefix("haply") {
            return haply(s, rest);
        }
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
                 `forcedimension[:INDEX]` (omega, sigma, delta) or `haply[:URL][@ID]` (a Haply \
                 Inverse3 through its service)"
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_haply_device_is_named_by_its_service_and_id() {
        let spec = |s: &str| s.parse::<DeviceSpec>();
        let haply = |url: Option<&str>, id: Option<&str>| DeviceSpec::Haply {
            url: url.map(str::to_owned),
            device_id: id.map(str::to_owned),
        };
        assert_eq!(spec("haply"), Ok(haply(None, None)));
        assert_eq!(spec("haply@049D"), Ok(haply(None, Some("049D"))));
        let url = "ws://127.0.0.1:4000";
        assert_eq!(spec(&format!("haply:{url}")), Ok(haply(Some(url), None)));
        assert_eq!(
            spec(&format!("haply:{url}@A1")),
            Ok(haply(Some(url), Some("A1")))
        );
        for bad in [
            "haply:localhost:10001",
            "haply@",
            "haplyx",
            "haply:ws://h/x@a/b",
        ] {
            let error = spec(bad).unwrap_err();
            assert!(error.contains(bad), "{error}");
        }
    }
}
