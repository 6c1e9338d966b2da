//! The layers of `docs/architecture.md` hold: the core crate depends on no Bevy crate, each
//! layer uses only those below, and no two parts of a folder (a file, or a subfolder taken
//! whole) import each other in a circle. Read from the source and the lock file of both
//! crates (this one and the trainer at the workspace's root), so that a change that breaks a
//! rule fails here, naming the file.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, lowest first: a module may use its own layer and those before it. The first
/// two are this crate's; the trainer re-exports them and adds the rest.
const LAYERS: [&[&str]; 4] = [
    &[
        "mesh",
        "fem",
        "pgd",
        "contact",
        "cutting",
        "dissection",
        "rods",
        "biliary",
        "dynamics",
        "devices",
        "scenario",
        "dense_sums",
        "parry_interop",
        "bench",
    ],
    &["store", "report", "history"],
    &["app"],
    &["cli"],
];

/// A module path inside the crate (`["contact", "pair"]`), with its source.
struct Module {
    file: PathBuf,
    is_folder: bool,
    text: String,
}

/// The workspace's root folder, where the trainer's package and `Cargo.lock` are.
fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The two crates' sources: this one's and the trainer's.
fn crates() -> [Crate; 2] {
    [
        Crate::new(Path::new(env!("CARGO_MANIFEST_DIR"))),
        Crate::new(&workspace()),
    ]
}

fn modules(package: &Path) -> BTreeMap<Vec<String>, Module> {
    let root = package.join("src");
    let mut out = BTreeMap::new();
    let mut folders = vec![root.clone()];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                if path != root.join("bin") {
                    folders.push(path);
                }
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let relative = path.strip_prefix(&root).unwrap().with_extension("");
            let mut name: Vec<String> = relative
                .iter()
                .map(|p| p.to_string_lossy().into_owned())
                .collect();
            let is_folder = name.last().is_some_and(|n| n == "mod");
            if is_folder || name == ["lib"] {
                name.pop();
            }
            let text = std::fs::read_to_string(&path).unwrap();
            out.insert(
                name,
                Module {
                    file: path,
                    is_folder,
                    text,
                },
            );
        }
    }
    out
}

/// The source without its tests and comments: what the module itself uses.
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or_default();
    text.lines()
        .map(|line| line.split("//").next().unwrap_or_default())
        .collect::<Vec<_>>()
        .join("\n")
}

/// Every `crate::…` or `super::…` path the code names, grouped imports spread out.
fn paths(code: &str) -> Vec<Vec<String>> {
    let mut out = vec![];
    for start in ["crate::", "super::"] {
        for (at, _) in code.match_indices(start) {
            if code[..at]
                .chars()
                .last()
                .is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':')
            {
                continue;
            }
            let rest = &code[at..];
            let raw: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            let after = &rest[raw.len()..];
            let head: Vec<String> = raw
                .split("::")
                .filter(|s| !s.is_empty())
                .map(str::to_owned)
                .collect();
            match after.strip_prefix('{') {
                Some(group) => {
                    let group = &group[..group.find('}').unwrap_or(group.len())];
                    for item in group.split(',') {
                        let mut path = head.clone();
                        path.extend(
                            item.trim()
                                .split("::")
                                .take_while(|s| !s.contains('{'))
                                .map(|s| s.split_whitespace().next().unwrap_or("").to_owned())
                                .filter(|s| !s.is_empty() && s != "self"),
                        );
                        out.push(path);
                    }
                }
                None => out.push(head),
            }
        }
    }
    out
}

struct Crate {
    modules: BTreeMap<Vec<String>, Module>,
    /// `(folder module, name)` → the submodule its `pub use` takes the name from.
    exports: BTreeMap<(Vec<String>, String), Vec<String>>,
}

impl Crate {
    /// The crate whose package is at `package`; a `crate::` path of the trainer that names a
    /// re-exported core module resolves to nothing, the core being below every layer.
    fn new(package: &Path) -> Self {
        let modules = modules(package);
        let mut exports = BTreeMap::new();
        for (name, module) in &modules {
            if !module.is_folder {
                continue;
            }
            for line in code(&module.text).split(';') {
                let Some(used) = line.trim().strip_prefix("pub use ") else {
                    continue;
                };
                let Some((sub, items)) = used.split_once("::") else {
                    continue;
                };
                let mut target = name.clone();
                target.push(sub.trim().to_owned());
                for item in items.split(|c: char| !(c.is_alphanumeric() || c == '_')) {
                    if !item.is_empty() {
                        exports.insert((name.clone(), item.to_owned()), target.clone());
                    }
                }
            }
        }
        Self { modules, exports }
    }

    /// The deepest module a path named from `here` lands in.
    fn resolve(&self, path: &[String], here: &[String]) -> Vec<String> {
        let mut at: Vec<String> = vec![];
        let mut parts = path;
        if parts.first().is_some_and(|p| p == "super") {
            at = here.to_vec();
            while parts.first().is_some_and(|p| p == "super") {
                at.pop();
                parts = &parts[1..];
            }
        } else if parts.first().is_some_and(|p| p == "crate") {
            parts = &parts[1..];
        }
        for part in parts {
            let mut next = at.clone();
            next.push(part.clone());
            if self.modules.contains_key(&next) {
                at = next;
            } else if let Some(target) = self.exports.get(&(at.clone(), part.clone())) {
                at = target.clone();
            } else {
                break;
            }
        }
        at
    }

    /// Each module's uses of other modules, outside its tests.
    fn uses(&self) -> BTreeMap<&Vec<String>, BTreeSet<Vec<String>>> {
        self.modules
            .iter()
            .map(|(name, module)| {
                let used = paths(&code(&module.text))
                    .iter()
                    .map(|p| self.resolve(p, name))
                    .filter(|t| !t.is_empty() && t != name)
                    .collect();
                (name, used)
            })
            .collect()
    }
}

fn layer(top: &str) -> Option<usize> {
    LAYERS.iter().position(|layer| layer.contains(&top))
}

/// Every package `package` depends on, itself included, as `Cargo.lock` lists them: for
/// every target and kind of dependency, so that nothing can bring one in sideways.
fn dependency_closure(lock: &str, package: &str) -> BTreeSet<String> {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for block in lock.split("[[package]]").skip(1) {
        let field = |key: &str| {
            block
                .lines()
                .find_map(|l| l.strip_prefix(key))
                .map(|v| v.trim().trim_matches('"').to_owned())
        };
        let Some(name) = field("name = ") else {
            continue;
        };
        let deps = block
            .split_once("dependencies = [")
            .map_or("", |(_, rest)| rest.split(']').next().unwrap_or(""));
        let names = deps
            .split(',')
            .filter_map(|d| d.trim().trim_matches('"').split(' ').next())
            .filter(|d| !d.is_empty())
            .map(str::to_owned);
        graph.entry(name).or_default().extend(names);
    }
    let mut seen = BTreeSet::new();
    let mut todo = vec![package.to_owned()];
    while let Some(next) = todo.pop() {
        if seen.insert(next.clone()) {
            todo.extend(graph.get(&next).into_iter().flatten().cloned());
        }
    }
    seen
}

/// The core builds and tests without the renderer: no `bevy` package, directly or through
/// another crate, is among its dependencies.
#[test]
fn the_core_crate_depends_on_no_bevy_crate() {
    let lock = std::fs::read_to_string(workspace().join("Cargo.lock")).unwrap();
    let closure = dependency_closure(&lock, env!("CARGO_PKG_NAME"));
    assert!(closure.contains("faer"), "the lock file was not read");
    let bevy: Vec<_> = closure.iter().filter(|p| p.starts_with("bevy")).collect();
    assert!(bevy.is_empty(), "the core depends on {bevy:?}");
    // The trainer does, through the same reading.
    assert!(dependency_closure(&lock, "pgd-surgery").contains("bevy_ecs"));
}

#[test]
fn each_layer_uses_only_the_layers_below_it() {
    let mut offences = vec![];
    for krate in crates() {
        offences.extend(layer_breaches(&krate));
    }
    assert!(offences.is_empty(), "{offences:#?}");
}

fn layer_breaches(krate: &Crate) -> Vec<String> {
    let mut offences = vec![];
    for (name, used) in krate.uses() {
        let Some(from) = name.first().and_then(|t| layer(t)) else {
            continue;
        };
        for target in used {
            let to = target.first().and_then(|t| layer(t));
            if to.is_some_and(|to| to > from) {
                offences.push(format!(
                    "{} uses crate::{}",
                    krate.modules[name].file.display(),
                    target.join("::")
                ));
            }
        }
    }
    offences
}

#[test]
fn no_folder_has_an_import_circle() {
    for krate in crates() {
        let circles = circles(&folder_graph(&krate));
        assert!(circles.is_empty(), "import circles: {circles:#?}");
    }
}

/// Within the folder two modules share, which part each lies in imports which.
fn folder_graph(krate: &Crate) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let mut graph: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (name, used) in krate.uses() {
        for target in used {
            let shared = name.iter().zip(&target).take_while(|(a, b)| a == b).count();
            if shared == name.len() || shared == target.len() {
                continue; // a module and its own submodule
            }
            graph
                .entry(name[..=shared].to_vec())
                .or_default()
                .insert(target[..=shared].to_vec());
        }
    }
    graph
}

/// The strongly connected components of more than one node (Tarjan).
fn circles(graph: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<Vec<String>> {
    struct Walk<'a> {
        graph: &'a BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        index: BTreeMap<&'a Vec<String>, (usize, usize)>,
        stack: Vec<&'a Vec<String>>,
        found: Vec<Vec<String>>,
    }
    impl<'a> Walk<'a> {
        fn visit(&mut self, node: &'a Vec<String>) -> usize {
            let order = self.index.len();
            self.index.insert(node, (order, order));
            self.stack.push(node);
            let mut low = order;
            for next in self.graph.get(node).into_iter().flatten() {
                let next_low = match self.index.get(next) {
                    None => self.visit(next),
                    Some(&(i, _)) if self.stack.contains(&next) => i,
                    Some(_) => continue,
                };
                low = low.min(next_low);
            }
            self.index.insert(node, (order, low));
            if low == order {
                let at = self.stack.iter().position(|n| *n == node).unwrap();
                let component: Vec<String> = self.stack.drain(at..).map(|n| n.join("::")).collect();
                if component.len() > 1 {
                    self.found.push(component);
                }
            }
            low
        }
    }
    let mut walk = Walk {
        graph,
        index: BTreeMap::new(),
        stack: vec![],
        found: vec![],
    };
    for node in graph.keys() {
        if !walk.index.contains_key(node) {
            walk.visit(node);
        }
    }
    walk.found
}

#[test]
fn the_checks_see_a_circle_and_a_layer_breach() {
    // The parser and the graph on made-up modules: a test of the checks themselves.
    let used = paths("use super::{pair::OrganPose, clearance::Clearance};\nuse crate::app::x;");
    let named = |p: &[&str]| used.iter().any(|u| u == p);
    assert_eq!(used.len(), 3, "{used:?}");
    assert!(named(&["super", "pair", "OrganPose"]), "{used:?}");
    assert!(named(&["super", "clearance", "Clearance"]), "{used:?}");
    assert!(named(&["crate", "app", "x"]), "{used:?}");
    let node = |s: &str| s.split("::").map(str::to_owned).collect::<Vec<_>>();
    let graph = BTreeMap::from([
        (node("contact::a"), BTreeSet::from([node("contact::b")])),
        (node("contact::b"), BTreeSet::from([node("contact::a")])),
        (node("contact::c"), BTreeSet::from([node("contact::a")])),
    ]);
    assert_eq!(circles(&graph), vec![vec!["contact::a", "contact::b"]]);
    assert!(layer("app") > layer("contact"));
    let lock = r#"
[[package]]
name = "core"
dependencies = [
 "faer",
 "plot 0.3.7",
]

[[package]]
name = "plot"
version = "0.3.7"
dependencies = ["bevy_color 0.19.1 (registry+https://example)"]
"#;
    let closure = dependency_closure(lock, "core");
    assert_eq!(
        closure,
        BTreeSet::from(["core", "faer", "plot", "bevy_color"].map(str::to_owned))
    );
}
