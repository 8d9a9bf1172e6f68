//! The shape of the source tree, checked: no import circle between the files of any crate, no
//! file that names an item of a layer above its own ([`LAYERS`]), and no file that does several
//! jobs (more than [`MAX_LOGIC_LINES`] lines of logic).
//!
//! A file depends on another when it names an item of it: a `use crate::...`, `use super::...`
//! or `use self::...` path, or an inline `crate::a::b` path in its code. Each path is resolved
//! to the deepest file module it names, so importing a type through a parent's re-export counts
//! as depending on the parent (import from the defining file instead). Test code is left out:
//! everything from a file's first `#[cfg(test)]` on, `tests.rs` files and `tests/` folders.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Lines of logic (not blank, not comment) a source file may hold before its tests.
const MAX_LOGIC_LINES: usize = 600;

const CRATES: [&str; 3] = ["common", "firmware", "sim-host"];

/// The crate root's name in the graph and in [`LAYERS`] (`lib.rs`, or `main.rs` in a crate
/// without a library); a binary's `main.rs` beside a `lib.rs` is the module `main`.
const ROOT: &str = "(crate root)";

/// Each crate's layers, lowest first: groups of top-level modules. A file may name items of
/// its own layer and of the layers below it, never of a layer above. Every top-level module
/// is placed, so a new one is placed on purpose.
const LAYERS: [(&str, &[&[&str]]); 3] = [
    (
        "common",
        &[
            // What every stage is written in; the root holds the exported macros (`param!`).
            &[ROOT, "math", "crc", "decimal", "ulog"],
            // Each stage declares its parameters.
            &["params"],
            // The flight log: its topics as plain data (the vehicle fills them) and the
            // logger that writes them with the parameters.
            &["logger"],
            // The two ends of the tick: typed sensor samples in, surfaces out.
            &["sensors", "actuators"],
            // The stages, and the wire formats of the two links (HIL frames carry samples
            // and surfaces).
            &["estimator", "guidance", "control", "battery", "link"],
            // The navigator drives guidance and control from the estimate; the failsafes
            // read the battery; tuning fits the models the control's gains are designed on.
            &["navigation", "failsafe", "tuning"],
            // The vehicle wires the stages: commander, modes, snapshot, requests.
            &["vehicle"],
            // The vehicle's stores and snapshot brought out: the ground link and the flash.
            &["gcs", "storage"],
        ],
    ),
    (
        "firmware",
        &[
            &[ROOT],
            // The application: the vehicle between its two ports.
            &["app"],
            // The boards that move its bytes (`mcu` is the binary's).
            &["sitl", "mcu"],
            &["main"],
        ],
    ),
    (
        "sim-host",
        &[
            // Output forms, the air, sensor models, mission files and the ULog reader: nothing
            // of sim-host.
            &[
                ROOT,
                "report",
                "environment",
                "sensors",
                "mission_file",
                "ulog_read",
            ],
            // The aircraft file, its sensors' configuration included.
            &["aircraft"],
            &["plant"],
            // The simulator end of the link: transports, lock-step, .tlog, QEMU.
            &["link"],
            // The linear tools and the chapter-4 scenarios on the nonlinear plant.
            &["analysis", "scenario"],
            // Firmware in the loop: a flight, its log and figures.
            &["flight"],
            // Campaigns of flights.
            &["campaign"],
            // The command-line front as library functions.
            &["commands"],
            // The binary: parsing and dispatch.
            &["main", "cli", "cli_campaign"],
        ],
    ),
];

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace")
        .to_path_buf()
}

/// The `.rs` files of a crate's `src/` that are not test code, by module path
/// (`["navigation", "executor"]` for `src/navigation/executor.rs`; `[]` for the crate root,
/// `["main"]` for a binary's `main.rs` beside a `lib.rs`).
fn modules(src: &Path) -> BTreeMap<Vec<String>, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("readable source folder") {
            let path = entry.expect("directory entry").path();
            if path.is_dir() {
                if path.file_name().is_some_and(|n| n != "tests") {
                    stack.push(path);
                }
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
            if stem == "tests" || stem.ends_with("_tests") {
                continue;
            }
            let rel = path.strip_prefix(src).expect("inside src");
            let mut module: Vec<String> = rel
                .parent()
                .into_iter()
                .flat_map(|p| p.components())
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            // A binary's root beside the library's is a module of its own, not the root.
            let binary_beside_lib =
                stem == "main" && module.is_empty() && src.join("lib.rs").is_file();
            if binary_beside_lib || !matches!(stem, "mod" | "lib" | "main") {
                module.push(stem.to_owned());
            }
            out.insert(module, path);
        }
    }
    out
}

/// The part of a file before its inline test module (`#[cfg(test)] mod tests { ... }`); a
/// `#[cfg(test)] mod tests;` declaration only names another file.
fn logic(text: &str) -> &str {
    let mut from = 0;
    while let Some(i) = text[from..].find("#[cfg(test)]") {
        let at = from + i;
        let item = text[at..].lines().nth(1).unwrap_or("");
        if item.trim_end().ends_with('{') {
            return &text[..at];
        }
        from = at + 1;
    }
    text
}

fn strip_comments(text: &str) -> String {
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Expands one `use` tree (`a::{b, c::{d, e}}`) into its paths.
fn expand_use(tree: &str) -> Vec<Vec<String>> {
    fn split_top(s: &str) -> Vec<&str> {
        let (mut depth, mut start, mut parts) = (0, 0, Vec::new());
        for (i, c) in s.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    parts.push(&s[start..i]);
                    start = i + 1;
                }
                _ => {}
            }
        }
        parts.push(&s[start..]);
        parts.into_iter().filter(|p| !p.trim().is_empty()).collect()
    }
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    match tree.find('{') {
        None => {
            let path = tree.split(" as ").next().unwrap_or("").to_owned();
            vec![path
                .split("::")
                .filter(|s| !s.is_empty())
                .map(str::to_owned)
                .collect()]
        }
        Some(open) => {
            let prefix: Vec<String> = tree[..open]
                .split("::")
                .filter(|s| !s.is_empty())
                .map(str::to_owned)
                .collect();
            let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
            split_top(inner)
                .into_iter()
                .flat_map(expand_use)
                .map(|rest| prefix.iter().cloned().chain(rest).collect())
                .collect()
        }
    }
}

/// Every path a file names: its `use` trees and inline `crate::` and `super::` paths.
fn paths(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(i) = rest.find("use ") {
        let before = rest[..i].chars().last();
        let after = &rest[i + 4..];
        rest = after;
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let Some(end) = after.find(';') else { break };
        let tree = &after[..end];
        if tree.contains('\n') && !tree.trim_start().starts_with(['c', 's']) {
            continue;
        }
        out.extend(expand_use(tree));
    }
    for root in ["crate::", "super::"] {
        let mut rest = code;
        while let Some(i) = rest.find(root) {
            let tail = &rest[i..];
            let end = tail
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(tail.len());
            let path: Vec<String> = tail[..end]
                .split("::")
                .filter(|s| !s.is_empty())
                .map(str::to_owned)
                .collect();
            // `super::{a, b}` is a use tree, already expanded above.
            if path.len() > 1 {
                out.push(path);
            }
            rest = &tail[end.max(1)..];
        }
    }
    out
}

/// The file module a path names, seen from `from` (`is_dir`: `from` is a `mod.rs`/root).
fn resolve(
    path: &[String],
    from: &[String],
    is_dir: bool,
    mods: &BTreeMap<Vec<String>, PathBuf>,
) -> Option<Vec<String>> {
    let mut base: Vec<String> = match path.first().map(String::as_str) {
        Some("crate") => Vec::new(),
        Some("super") => {
            let mut b = from.to_vec();
            if !is_dir || !b.is_empty() {
                b.pop();
            }
            b
        }
        Some("self") => from.to_vec(),
        // A relative path into a child module (`pub use executor::Navigator;` in a mod.rs).
        Some(child) => {
            let mut b = from.to_vec();
            b.push(child.to_owned());
            if !mods.contains_key(&b) {
                return None;
            }
            from.to_vec()
        }
        None => return None,
    };
    let skip = usize::from(matches!(path[0].as_str(), "crate" | "super" | "self"));
    let mut segs = path[skip..].iter().peekable();
    while segs.peek().is_some_and(|s| *s == "super") {
        segs.next();
        base.pop();
    }
    let mut best = base.clone();
    for s in segs {
        base.push(s.clone());
        if mods.contains_key(&base) {
            best = base.clone();
        } else {
            break;
        }
    }
    Some(best)
}

fn graph(src: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let mods = modules(src);
    let mut g = BTreeMap::new();
    for (m, file) in &mods {
        let text = std::fs::read_to_string(file).expect("readable source");
        let code = strip_comments(logic(&text));
        let stem = file.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        let is_dir = matches!(stem, "mod" | "lib" | "main");
        let deps: BTreeSet<Vec<String>> = paths(&code)
            .iter()
            .filter_map(|p| resolve(p, m, is_dir, &mods))
            .filter(|d| d != m)
            .collect();
        g.insert(m.clone(), deps);
    }
    g
}

/// Strongly connected components of more than one file (Tarjan).
fn circles(g: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        index: BTreeMap<&'a Vec<String>, usize>,
        low: BTreeMap<&'a Vec<String>, usize>,
        stack: Vec<&'a Vec<String>>,
        on: BTreeSet<&'a Vec<String>>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a Vec<String>) {
        t.index.insert(v, t.next);
        t.low.insert(v, t.next);
        t.next += 1;
        t.stack.push(v);
        t.on.insert(v);
        for w in t.g.get(v).into_iter().flatten() {
            let Some((w, _)) = t.g.get_key_value(w) else {
                continue;
            };
            if !t.index.contains_key(w) {
                visit(t, w);
                let lw = t.low[w];
                let lv = t.low.get_mut(v).expect("visited");
                *lv = (*lv).min(lw);
            } else if t.on.contains(w) {
                let iw = t.index[w];
                let lv = t.low.get_mut(v).expect("visited");
                *lv = (*lv).min(iw);
            }
        }
        if t.low[v] == t.index[v] {
            let mut scc = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(w);
                scc.push(if w.is_empty() {
                    "(crate root)".to_owned()
                } else {
                    w.join("::")
                });
                if w == v {
                    break;
                }
            }
            if scc.len() > 1 {
                scc.sort();
                t.out.push(scc);
            }
        }
    }
    let mut t = T {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in g.keys() {
        if !t.index.contains_key(v) {
            visit(&mut t, v);
        }
    }
    t.out
}

/// The name of a module's top-level module, as [`LAYERS`] lists it.
fn top(module: &[String]) -> &str {
    module.first().map_or(ROOT, String::as_str)
}

/// The layer of a module: the index in `layers` of the group holding its top-level module.
fn layer_of(module: &[String], layers: &[&[&str]]) -> Option<usize> {
    layers.iter().position(|l| l.contains(&top(module)))
}

/// The top-level modules of a crate that no layer holds, and the names a layer holds that are
/// no top-level module of the crate.
fn unplaced(src: &Path, layers: &[&[&str]]) -> (BTreeSet<String>, BTreeSet<String>) {
    let tops: BTreeSet<String> = modules(src).keys().map(|m| top(m).to_owned()).collect();
    let placed: BTreeSet<String> = layers
        .iter()
        .flat_map(|l| l.iter())
        .map(|s| s.to_string())
        .collect();
    (
        tops.difference(&placed).cloned().collect(),
        placed.difference(&tops).cloned().collect(),
    )
}

/// Every file that names an item of a layer above its own: the file, what it names and both
/// layers, paths relative to `src`.
fn upward_imports(src: &Path, layers: &[&[&str]]) -> Vec<String> {
    let mods = modules(src);
    let file = |m: &Vec<String>| {
        mods.get(m)
            .and_then(|p| p.strip_prefix(src).ok())
            .map_or_else(|| m.join("::"), |p| p.display().to_string())
    };
    let name = |i: usize| layers.get(i).map_or("?".to_owned(), |l| l.join("/"));
    let mut found = Vec::new();
    for (m, deps) in graph(src) {
        let Some(own) = layer_of(&m, layers) else {
            continue;
        };
        for d in deps {
            match layer_of(&d, layers) {
                Some(l) if l > own => found.push(format!(
                    "{} (layer {own}: {}) names {} (layer {l}: {})",
                    file(&m),
                    name(own),
                    file(&d),
                    name(l)
                )),
                _ => {}
            }
        }
    }
    found
}

#[test]
fn no_crate_has_an_import_circle_between_its_files() {
    let mut found = Vec::new();
    for krate in CRATES {
        for c in circles(&graph(&workspace().join(krate).join("src"))) {
            found.push(format!("{krate}: {}", c.join(" <-> ")));
        }
    }
    assert!(found.is_empty(), "import circles:\n{}", found.join("\n"));
}

#[test]
fn no_source_file_holds_more_than_600_lines_of_logic() {
    let mut big = Vec::new();
    for krate in CRATES {
        for file in modules(&workspace().join(krate).join("src")).values() {
            let text = std::fs::read_to_string(file).expect("readable source");
            let n = strip_comments(logic(&text))
                .lines()
                .filter(|l| !l.trim().is_empty())
                .count();
            if n > MAX_LOGIC_LINES {
                big.push(format!("{} ({n})", file.display()));
            }
        }
    }
    assert!(
        big.is_empty(),
        "files over {MAX_LOGIC_LINES} lines of logic:\n{}",
        big.join("\n")
    );
}

#[test]
fn the_circle_finder_sees_a_circle_through_a_re_export() {
    // a.rs uses b; b.rs uses a type that mod.rs re-exports from a: a circle through the parent.
    let dir = tempfile::tempdir().expect("temporary folder");
    let src = dir.path();
    std::fs::create_dir(src.join("m")).expect("folder");
    std::fs::write(src.join("lib.rs"), "pub mod m;\n").expect("write");
    std::fs::write(
        src.join("m/mod.rs"),
        "pub mod a;\npub mod b;\npub use a::A;\n",
    )
    .expect("write");
    std::fs::write(src.join("m/a.rs"), "use super::b::B;\npub struct A(B);\n").expect("write");
    std::fs::write(
        src.join("m/b.rs"),
        "pub struct B;\nfn f(_: super::A) {}\nuse crate::m::A;\n",
    )
    .expect("write");
    let c = circles(&graph(src));
    assert_eq!(c, vec![vec!["m".to_owned(), "m::a".into(), "m::b".into()]]);
    // Importing from the defining file breaks it.
    std::fs::write(src.join("m/b.rs"), "pub struct B;\n").expect("write");
    assert!(circles(&graph(src)).is_empty());
}

#[test]
fn every_top_level_module_is_placed_in_exactly_one_layer() {
    let mut wrong = Vec::new();
    for (krate, layers) in LAYERS {
        let (missing, stale) = unplaced(&workspace().join(krate).join("src"), layers);
        for m in missing {
            wrong.push(format!("{krate}: `{m}` is in no layer: place it in LAYERS"));
        }
        for m in stale {
            wrong.push(format!("{krate}: LAYERS names `{m}`, no top-level module"));
        }
        let mut seen = BTreeSet::new();
        for m in layers.iter().flat_map(|l| l.iter()) {
            if !seen.insert(m) {
                wrong.push(format!("{krate}: `{m}` is in two layers"));
            }
        }
    }
    assert_eq!(LAYERS.map(|(k, _)| k), CRATES, "every crate has its layers");
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn no_file_imports_from_a_layer_above_its_own() {
    let mut found = Vec::new();
    for (krate, layers) in LAYERS {
        for u in upward_imports(&workspace().join(krate).join("src"), layers) {
            found.push(format!("{krate}: {u}"));
        }
    }
    assert!(
        found.is_empty(),
        "imports from a layer above:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_layer_check_sees_an_upward_import_through_a_re_export_and_an_unplaced_module() {
    // low/a.rs names a type that high/mod.rs re-exports from high/h.rs: it depends on high.
    let dir = tempfile::tempdir().expect("temporary folder");
    let src = dir.path();
    for d in ["low", "high"] {
        std::fs::create_dir(src.join(d)).expect("folder");
    }
    std::fs::write(src.join("lib.rs"), "pub mod high;\npub mod low;\n").expect("write");
    std::fs::write(src.join("low/mod.rs"), "pub mod a;\n").expect("write");
    std::fs::write(src.join("low/a.rs"), "pub fn f(_: crate::high::H) {}\n").expect("write");
    std::fs::write(src.join("high/mod.rs"), "pub mod h;\npub use h::H;\n").expect("write");
    std::fs::write(src.join("high/h.rs"), "pub struct H;\n").expect("write");
    let layers: &[&[&str]] = &[&[ROOT, "low"], &["high"]];
    assert_eq!(
        upward_imports(src, layers),
        ["low/a.rs (layer 0: (crate root)/low) names high/mod.rs (layer 1: high)"]
    );
    // Nothing runs down the other way, and with the layers swapped nothing runs up.
    assert!(upward_imports(src, &[&[ROOT, "high"], &["low"]]).is_empty());
    // A new top-level module is in no layer until it is placed.
    std::fs::write(src.join("extra.rs"), "pub struct E;\n").expect("write");
    let (missing, stale) = unplaced(src, layers);
    assert_eq!(missing, BTreeSet::from(["extra".to_owned()]));
    assert!(stale.is_empty());
}
