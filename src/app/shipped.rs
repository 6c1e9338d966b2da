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

/// Calls `$then!` with every shipped scenario's stem, in the menu's order; the first is the
/// trainer's default exercise.
macro_rules! with_shipped_stems {
    ($then:ident) => {
        $then!(
            "liver-steady-press",
            "abdomen-tour",
            "bimanual-liver-lift",
            "bimanual-traction-countertraction",
            "cornea-radial-keratotomy",
            "duodenum-navigation",
            "gallbladder-gentle-press",
            "gallbladder-grasp-retract",
            "gallbladder-liver-bed-dissection",
            "gallbladder-liver-two-ports",
            "gallbladder-retraction",
            "lap-chole-clip-and-cut",
            "lap-chole-full",
            "liver-capsule-incision",
            "liver-laparoscopic-press",
            "pancreas-palpation",
            "pancreas-tour",
        )
    };
}

/// Each shipped scenario's file name and text; the first is the trainer's default exercise.
pub const SHIPPED_SCENARIOS: &[(&str, &str)] = with_shipped_stems!(shipped);

/// A shipped scenario with its two scripted runs (`scenarios/runs/<stem>.competent.csv` and
/// `.careless.csv`, written for the coarse organs), built in for `trainer soak`.
pub struct ShippedRun {
    pub file: &'static str,
    pub scenario: &'static str,
    pub competent_file: &'static str,
    pub competent: &'static str,
    pub careless_file: &'static str,
    pub careless: &'static str,
}

/// Each stem's [`ShippedRun`].
macro_rules! shipped_runs {
    ($($stem:literal),* $(,)?) => {
        &[$(ShippedRun {
            file: concat!("scenarios/", $stem, ".scenario.ron"),
            scenario: include_str!(concat!("../../scenarios/", $stem, ".scenario.ron")),
            competent_file: concat!("scenarios/runs/", $stem, ".competent.csv"),
            competent: include_str!(concat!("../../scenarios/runs/", $stem, ".competent.csv")),
            careless_file: concat!("scenarios/runs/", $stem, ".careless.csv"),
            careless: include_str!(concat!("../../scenarios/runs/", $stem, ".careless.csv")),
        }),*]
    };
}

/// Every shipped scenario's runs, in the menu's order.
pub const SHIPPED_RUNS: &[ShippedRun] = with_shipped_stems!(shipped_runs);

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
        let mut with_runs: Vec<&str> = SHIPPED_RUNS.iter().map(|run| run.file).collect();
        with_runs.sort();
        let files: Vec<&str> = built_in.iter().map(|(file, _)| file.as_str()).collect();
        assert_eq!(with_runs, files, "every shipped scenario has its runs");
    }
}
