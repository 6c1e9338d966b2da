//! The scenarios shipped in `scenarios/`, built into the program: the window's menu offers
//! them from any directory (a file of the same name in the scenarios folder is offered
//! instead), and the web page, which has no folder to read, offers exactly these.

/// `scenarios/<stem>.scenario.ron` and its text, for each stem.
macro_rules! shipped {
    ($($stem:literal),* $(,)?) => {
        &[$((
            concat!("scenarios/", $stem, ".scenario.ron"),
            include_str!(concat!("../../scenarios/", $stem, ".scenario.ron")),
        )),*]
    };
}

/// Each shipped scenario's file name and text; the first is the trainer's default exercise.
pub const SHIPPED_SCENARIOS: &[(&str, &str)] = shipped!(
    "liver-steady-press",
    "abdomen-tour",
    "cornea-radial-keratotomy",
    "duodenum-navigation",
    "gallbladder-gentle-press",
    "gallbladder-grasp-retract",
    "gallbladder-liver-two-ports",
    "gallbladder-retraction",
    "liver-capsule-incision",
    "liver-laparoscopic-press",
    "pancreas-palpation",
    "pancreas-tour",
);

#[cfg(test)]
mod tests {
    use super::*;

    /// Every file in `scenarios/` is built in, with its current text, and nothing else is.
    #[test]
    fn the_built_in_scenarios_are_the_shipped_files() {
        let mut on_disk: Vec<(String, String)> = std::fs::read_dir("scenarios")
            .unwrap()
            .map(|entry| entry.unwrap().path())
            .filter(|path| path.to_string_lossy().ends_with(".scenario.ron"))
            .map(|path| {
                let text = std::fs::read_to_string(&path).unwrap();
                (path.to_string_lossy().into_owned(), text)
            })
            .collect();
        on_disk.sort();
        let mut built_in: Vec<(String, String)> = SHIPPED_SCENARIOS
            .iter()
            .map(|(file, text)| (file.to_string(), text.to_string()))
            .collect();
        built_in.sort();
        assert_eq!(built_in, on_disk);
    }
}
