//! Module-name resolution: which identifiers in a module string are one declared
//! module and which are runs of single-letter modules.
//!
//! Owns: the contract rule "`FF` is two `F` unless a module `FF` is declared".
//! A run of letters that is not declared is split into one module per letter (the
//! parameters, if any, belong to the last letter); a name that cannot be split
//! (digits, `_`) must be declared. Must not check arity or meaning (that is `check`).

use crate::ast::{File, Item, ModName, Module, Stmt};
use crate::diagnostic::{Code, Diagnostic};
use crate::span::Span;
use std::collections::HashSet;

/// The names declared as modules in a file: `module` items and `element`s at the
/// top, plus one lsystem's own `module` statements.
#[derive(Clone, Debug, Default)]
pub struct Scope {
    names: HashSet<String>,
}

impl Scope {
    pub fn file(file: &File) -> Scope {
        let mut names = HashSet::new();
        for item in &file.items.stmts {
            match &item.node {
                Item::Module(m) => {
                    names.insert(m.name.name.clone());
                }
                Item::Element(e) => {
                    names.insert(e.name.name.clone());
                }
                _ => {}
            }
        }
        Scope { names }
    }

    /// The file scope plus the lsystem's own declarations.
    pub fn with_lsystem(&self, body: &[crate::ast::Node<Stmt>]) -> Scope {
        let mut names = self.names.clone();
        for s in body {
            if let Stmt::Module(m) = &s.node {
                names.insert(m.name.name.clone());
            }
        }
        Scope { names }
    }

    pub fn declares(&self, name: &str) -> bool {
        self.names.contains(name)
    }
}

/// Whether a name is one module without declaration: a single letter.
pub fn is_letter(name: &str) -> bool {
    let mut cs = name.chars();
    matches!((cs.next(), cs.next()), (Some(c), None) if c.is_alphabetic())
}

/// Whether an undeclared name can be split into single letters.
pub fn splits(name: &str) -> bool {
    name.chars().all(char::is_alphabetic)
}

pub fn resolve(file: &mut File, diags: &mut Vec<Diagnostic>) {
    let top = Scope::file(file);
    for item in &mut file.items.stmts {
        let Item::Lsystem(ls) = &mut item.node else {
            continue;
        };
        let scope = top.with_lsystem(&ls.body.stmts);
        for stmt in &mut ls.body.stmts {
            match &mut stmt.node {
                Stmt::Axiom(ms) | Stmt::Ignore(ms) => split_list(ms, &scope, diags),
                Stmt::Rule(r) => {
                    if let Some(l) = &mut r.left {
                        split_list(l, &scope, diags);
                    }
                    if let Some(rc) = &mut r.right {
                        split_list(rc, &scope, diags);
                    }
                    split_list(&mut r.succ, &scope, diags);
                    check_pred(&r.pred, &scope, diags);
                }
                _ => {}
            }
        }
    }
}

fn check_pred(m: &Module, scope: &Scope, diags: &mut Vec<Diagnostic>) {
    let ModName::Name(name) = &m.name else {
        return;
    };
    if scope.declares(name) || is_letter(name) {
        return;
    }
    if splits(name) {
        let letters: Vec<String> = name.chars().map(String::from).collect();
        diags.push(
            Diagnostic::error(
                Code::UndeclaredModule,
                format!("`{name}` is not declared, so it is {} modules, and a rule rewrites one module", letters.len()),
            )
            .primary(m.name_span, format!("read as {}", letters.join(" ")))
            .help(format!(
                "declare it with `module {name};` (with its parameters) to make it one module, or use context: `{} < {}`",
                letters[..letters.len() - 1].join(""),
                letters[letters.len() - 1]
            )),
        );
    } else {
        diags.push(undeclared(name, m.name_span));
    }
}

fn undeclared(name: &str, span: Span) -> Diagnostic {
    let d = Diagnostic::error(Code::UndeclaredModule, format!("module `{name}` is not declared"))
        .primary(span, "multi-letter names must be declared");
    let letters: String = name.chars().take_while(|c| c.is_alphabetic()).collect();
    let digits: String = name[letters.len()..].to_string();
    if !letters.is_empty() && !digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit()) {
        d.help(format!(
            "declare it with `module {name};`, or if you meant a parameter write `{letters}({digits})`"
        ))
    } else {
        d.help(format!("declare it with `module {name}(…);` at the top of the file or in the lsystem"))
    }
}

fn word_like(name: &str) -> bool {
    let mut cs = name.chars();
    let first = cs.next();
    name.chars().count() >= 3
        && first.is_some_and(char::is_uppercase)
        && cs.all(char::is_lowercase)
}

fn split_list(ms: &mut Vec<Module>, scope: &Scope, diags: &mut Vec<Diagnostic>) {
    if !ms.iter().any(|m| needs_split(m, scope)) {
        for m in ms.iter() {
            if let ModName::Name(n) = &m.name {
                if !scope.declares(n) && !is_letter(n) && !splits(n) {
                    diags.push(undeclared(n, m.name_span));
                }
            }
        }
        return;
    }
    let old = std::mem::take(ms);
    for m in old {
        if !needs_split(&m, scope) {
            if let ModName::Name(n) = &m.name {
                if !scope.declares(n) && !is_letter(n) && !splits(n) {
                    diags.push(undeclared(n, m.name_span));
                }
            }
            ms.push(m);
            continue;
        }
        let ModName::Name(name) = &m.name else {
            unreachable!("needs_split only accepts names")
        };
        if word_like(name) {
            let spaced: Vec<String> = name.chars().map(String::from).collect();
            diags.push(
                Diagnostic::warning(
                    Code::SplitWord,
                    format!("`{name}` is read as {} single-letter modules", spaced.len()),
                )
                .primary(m.name_span, format!("read as {}", spaced.join(" ")))
                .help(format!(
                    "declare `module {name};` if you meant one module; write `{}` to keep the letters and silence this",
                    spaced.join(" ")
                )),
            );
        }
        let chars: Vec<(usize, char)> = name.char_indices().collect();
        let base = m.name_span.start as usize;
        let last = chars.len() - 1;
        for (k, &(off, c)) in chars.iter().enumerate() {
            let start = base + off;
            let end = start + c.len_utf8();
            let name_span = Span::new(start, end);
            let (args, span) = if k == last {
                (m.args.clone(), Span::new(start, m.span.end as usize))
            } else {
                (None, name_span)
            };
            ms.push(Module {
                name: ModName::Name(c.to_string()),
                name_span,
                args,
                span,
            });
        }
    }
}

fn needs_split(m: &Module, scope: &Scope) -> bool {
    match &m.name {
        ModName::Name(n) => !scope.declares(n) && !is_letter(n) && splits(n),
        _ => false,
    }
}
