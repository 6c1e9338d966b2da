//! Parsers of the binaries' option values, with errors that say the range or the form.

use crate::contact::{check_spacing, check_subdivisions};
use crate::cutting::CutPattern;
use crate::fem::Inclusion;

/// A `--subdivide` count within [`crate::contact::SUBDIVISIONS`].
pub fn parse_subdivisions(text: &str) -> Result<u8, String> {
    let n: u8 = text.parse().map_err(|e| format!("`{text}`: {e}"))?;
    check_subdivisions(n)
}

/// A `--sparse` spacing (mm) within [`crate::contact::SPARSE_SPACINGS_MM`].
pub fn parse_spacing(text: &str) -> Result<u8, String> {
    let mm: u8 = text.parse().map_err(|e| format!("`{text}`: {e}"))?;
    check_spacing(mm)
}

/// A force limit in newtons (`--max-force-n`): finite, from 0 to
/// [`crate::devices::MAX_FORCE_LIMIT_N`]. A negative one would turn the force against the hand.
pub fn parse_force_limit_n(text: &str) -> Result<f64, String> {
    let force_n: f64 = text.trim().parse().map_err(|e| format!("`{text}`: {e}"))?;
    crate::devices::check_force_limit(force_n)
}

/// A duration in seconds that must be more than zero and finite (`--exit-after-s`).
pub fn parse_positive_seconds(text: &str) -> Result<f64, String> {
    let seconds: f64 = text.trim().parse().map_err(|e| format!("`{text}`: {e}"))?;
    match seconds.is_finite() && seconds > 0.0 {
        true => Ok(seconds),
        false => Err(format!(
            "{seconds} is not a duration: seconds, more than 0 and finite"
        )),
    }
}

/// A duration in seconds that may be zero, finite (`--screenshot-after-s`).
pub fn parse_seconds(text: &str) -> Result<f64, String> {
    let seconds: f64 = text.trim().parse().map_err(|e| format!("`{text}`: {e}"))?;
    match seconds.is_finite() && seconds >= 0.0 {
        true => Ok(seconds),
        false => Err(format!(
            "{seconds} is not a duration: seconds, 0 or more and finite"
        )),
    }
}

/// A penalty's stiffness ratio: positive and finite.
pub fn parse_stiffness_ratio(text: &str) -> Result<f64, String> {
    let ratio: f64 = text.parse().map_err(|e| format!("`{text}`: {e}"))?;
    match ratio.is_finite() && ratio > 0.0 {
        true => Ok(ratio),
        false => Err(format!(
            "`{text}`: a penalty is a positive, finite number of times the tissue's stiffness"
        )),
    }
}

/// Reads a point `X,Y,Z` in millimetres, as `pgd indent --at` takes it.
pub fn parse_point_mm(text: &str) -> Result<[f64; 3], String> {
    let [x, y, z] = comma_numbers(text, "X,Y,Z (millimetres)")?;
    Ok([x, y, z])
}

/// Reads `X,Y,Z,RADIUS,RATIO` (lengths in mm) as `pgd build --inclusion` takes it.
pub fn parse_inclusion(text: &str) -> Result<Inclusion, String> {
    let [x, y, z, radius_mm, stiffness_ratio] =
        comma_numbers(text, "X,Y,Z,RADIUS,RATIO (millimetres, ratio)")?;
    let inclusion = Inclusion {
        centre_m: [x, y, z].map(|c| c * 1e-3),
        radius_m: radius_mm * 1e-3,
        stiffness_ratio,
    };
    inclusion.validate().map_err(|e| format!("`{text}`: {e}"))?;
    Ok(inclusion)
}

/// `N` comma-separated finite numbers, or an error naming the `expected` layout.
fn comma_numbers<const N: usize>(text: &str, expected: &str) -> Result<[f64; N], String> {
    let numbers: Vec<f64> = text
        .split(',')
        .map(|part| part.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("`{text}`: {e}; expected {expected}"))?;
    let count = numbers.len();
    match <[f64; N]>::try_from(numbers) {
        Ok(values) if values.iter().all(|v| v.is_finite()) => Ok(values),
        Ok(_) => Err(format!("`{text}`: not all finite; expected {expected}")),
        Err(_) => Err(format!(
            "`{text}`: {count} numbers; expected {N}: {expected}"
        )),
    }
}

/// A cut pattern of `pgd validate --cuts`: `radial:N` (the cornea) or `straight:N` (an
/// organ's accessible face), N incisions (N ≥ 1).
pub fn parse_cut_pattern(text: &str) -> Result<CutPattern, String> {
    let count = |n: &str| n.parse::<usize>().ok().filter(|&n| n >= 1);
    let pattern = match text.split_once(':') {
        Some(("radial", n)) => count(n).map(CutPattern::Radial),
        Some(("straight", n)) => count(n).map(CutPattern::Straight),
        _ => None,
    };
    pattern
        .ok_or_else(|| format!("{text}: expected radial:N or straight:N, N incisions (at least 1)"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_options_take_their_range_and_name_what_is_wrong() {
        assert_eq!(parse_subdivisions("3"), Ok(3));
        assert!(parse_subdivisions("0").unwrap_err().contains("1 to 8"));
        assert!(parse_subdivisions("9").unwrap_err().contains("1 to 8"));
        assert!(parse_subdivisions("two").unwrap_err().contains("`two`"));
        assert_eq!(parse_spacing("6"), Ok(6));
        assert!(parse_spacing("0").unwrap_err().contains("1 to 50 mm"));
        assert!(parse_spacing("51").unwrap_err().contains("1 to 50 mm"));
        assert!(parse_spacing("6.5").unwrap_err().contains("`6.5`"));
        assert_eq!(parse_stiffness_ratio("1e3"), Ok(1000.0));
        for bad in ["0", "-1", "inf", "NaN"] {
            assert!(parse_stiffness_ratio(bad).is_err(), "{bad}");
        }
    }
}
