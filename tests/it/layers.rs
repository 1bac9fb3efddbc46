//! The layers of the library (docs/architecture.md): every module uses only
//! modules of lower layers, so there is no cycle between them. Read from the
//! sources' `crate::…` paths; unit tests (`#[cfg(test)]` and `tests.rs`) may
//! reach anywhere.

use crate::support::root;
use std::path::Path;

/// Each top-level module of `src/` and its layer; a module may use only
/// modules of strictly lower layers. A new module must be placed here.
const LAYERS: &[(&str, u32)] = &[
    ("span", 0),
    ("number", 0),
    ("geometry", 0),
    ("diagnostic", 1),
    ("path", 1),
    ("organ", 2),
    ("lexer", 2),
    ("ast", 3),
    ("parser", 5),
    ("trivia", 4),
    ("resolve", 4),
    ("dump", 4),
    ("write", 0),
    ("source", 6),
    ("fmt", 5),
    ("builtins", 5),
    ("query", 5),
    ("vm", 6),
    ("check", 7),
    ("frontend", 8),
    ("compile", 8),
    ("derive", 9),
    ("turtle", 10),
    ("env", 11),
    ("render", 11),
    ("run", 12),
    ("edit", 12),
    ("infer", 12),
    ("lsp", 12),
    ("studio", 13),
];

fn layer(module: &str) -> Option<u32> {
    LAYERS.iter().find(|(m, _)| *m == module).map(|(_, l)| *l)
}

fn sources(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).expect("src").flatten() {
        let p = e.path();
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The top-level modules a text names after `crate::`, also in groups such as
/// `use crate::{resolve, trivia};`.
fn used_modules(text: &str) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = Vec::new();
    for (i, _) in text.match_indices("crate::") {
        let rest = &text[i + 7..];
        if let Some(group) = rest.strip_prefix('{') {
            let inner = &group[..group.find('}').unwrap_or(group.len())];
            out.extend(inner.split(',').map(ident).filter(|n| !n.is_empty()));
        } else {
            out.push(ident(rest));
        }
    }
    out.retain(|n| !n.is_empty());
    out
}

#[test]
fn modules_use_only_lower_layers() {
    let src = root().join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    files.sort();
    let mut problems = Vec::new();
    let mut checked = 0;
    for path in files {
        let rel = path.strip_prefix(&src).expect("under src");
        let first = rel
            .components()
            .next()
            .and_then(|c| c.as_os_str().to_str())
            .unwrap_or("");
        let module = first.trim_end_matches(".rs");
        if matches!(module, "lib" | "main" | "cli") || path.ends_with("tests.rs") {
            continue;
        }
        let Some(own) = layer(module) else {
            problems.push(format!(
                "{module}: not placed in a layer (tests/it/layers.rs)"
            ));
            continue;
        };
        let text = std::fs::read_to_string(&path).expect("read");
        let text = text.split("#[cfg(test)]").next().unwrap_or("");
        for used in used_modules(text) {
            if used == module {
                continue;
            }
            match layer(&used) {
                Some(l) if l < own => {}
                Some(l) => problems.push(format!(
                    "{}: `{module}` (layer {own}) uses `{used}` (layer {l})",
                    rel.display()
                )),
                None => problems.push(format!("{}: uses unknown `{used}`", rel.display())),
            }
        }
        checked += 1;
    }
    problems.sort();
    problems.dedup();
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert!(checked > 50, "only {checked} files read");
}
