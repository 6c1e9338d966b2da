//! The `pgd` options that take comma-separated numbers: what they accept, and the errors that
//! name what was expected.

use pgd_surgery::cli::{parse_inclusion, parse_point_mm};

#[test]
fn a_point_is_three_finite_millimetre_values() {
    assert_eq!(parse_point_mm("1.5, -2,30"), Ok([1.5, -2.0, 30.0]));
    let short = parse_point_mm("1,2").unwrap_err();
    assert!(
        short.contains("2 numbers") && short.contains("X,Y,Z"),
        "{short}"
    );
    let word = parse_point_mm("a,2,3").unwrap_err();
    assert!(word.contains("`a,2,3`") && word.contains("X,Y,Z"), "{word}");
    let infinite = parse_point_mm("1,2,inf").unwrap_err();
    assert!(infinite.contains("finite"), "{infinite}");
}

#[test]
fn an_inclusion_is_five_values_in_millimetres_and_a_ratio() {
    let inclusion = parse_inclusion("10,-5,30,7,6").unwrap();
    assert_eq!(inclusion.centre_m, [0.010, -0.005, 0.030]);
    assert_eq!(inclusion.radius_m, 0.007);
    assert_eq!(inclusion.stiffness_ratio, 6.0);
    let four = parse_inclusion("10,-5,30,7").unwrap_err();
    assert!(
        four.contains("4 numbers") && four.contains("RADIUS,RATIO"),
        "{four}"
    );
    let negative = parse_inclusion("10,-5,30,-7,6").unwrap_err();
    assert!(negative.contains("`10,-5,30,-7,6`"), "{negative}");
}
