//! [`Progress`] on the terminal, with indicatif: one bar per stage, hidden when stderr is not a
//! terminal (CI logs get one line per stage instead).

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};

use crate::pgd::Progress;

pub struct Bar {
    bar: ProgressBar,
    terminal: bool,
}

impl Default for Bar {
    fn default() -> Self {
        let bar = ProgressBar::new(0);
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix:>22} [{bar:32}] {pos}/{len} {elapsed_precise} (eta {eta}) {msg}",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        );
        Self {
            bar,
            terminal: std::io::stderr().is_terminal(),
        }
    }
}

impl Progress for Bar {
    fn start(&self, stage: &str, total: u64) {
        self.bar.set_prefix(stage.to_string());
        self.bar.set_length(total);
        self.bar.set_position(0);
        self.bar.set_message("");
        if !self.terminal {
            eprintln!("{stage}: {total} to do");
        }
    }

    fn advance(&self, amount: u64) {
        self.bar.inc(amount);
    }

    fn message(&self, text: &str) {
        self.bar.set_message(text.to_string());
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}
