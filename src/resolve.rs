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

/// Multi-letter modules the language itself defines (keywords in module strings).
pub fn is_builtin(name: &str) -> bool {
    name == "tropism"
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
        let mut r = Resolver {
            scope: &scope,
            diags,
            reported: HashSet::new(),
        };
        for stmt in &mut ls.body.stmts {
            match &mut stmt.node {
                Stmt::Axiom(ms) | Stmt::Ignore(ms) | Stmt::Consider(ms) => r.split_list(ms),
                Stmt::Rule(rule) => {
                    if let Some(l) = &mut rule.left {
                        r.split_list(l);
                    }
                    if let Some(rc) = &mut rule.right {
                        r.split_list(rc);
                    }
                    r.split_list(&mut rule.succ);
                    r.check_pred(rule);
                }
                _ => {}
            }
        }
    }
}

struct Resolver<'a> {
    scope: &'a Scope,
    diags: &'a mut Vec<Diagnostic>,
    /// Undeclared names already reported in this lsystem (one error per name).
    reported: HashSet<String>,
}

impl Resolver<'_> {
    fn check_pred(&mut self, rule: &crate::ast::Rule) {
        let m = &rule.pred;
        let ModName::Name(name) = &m.name else {
            return;
        };
        if self.scope.declares(name) || is_letter(name) {
            return;
        }
        let label_trap = rule.label.as_ref().filter(|l| is_letter(&l.name));
        if splits(name) {
            let letters: Vec<String> = name.chars().map(String::from).collect();
            let mut d = Diagnostic::error(
                Code::UndeclaredModule,
                format!(
                    "`{name}` is not declared, so it is {} modules, and a rule rewrites one module",
                    letters.len()
                ),
            )
            .primary(m.name_span, format!("read as {}", letters.join(" ")));
            d = if let Some(l) = label_trap {
                d.secondary(l.span, "read as a rule label").help(format!(
                    "`{0}:` is a rule label; for the predecessor `{0}` with a condition write `{0} : {name} …` with a space",
                    l.name
                ))
            } else if letters.len() == 2 {
                d.help(format!(
                    "declare it with `module {name}{};` to make it one module, or use context: `{} < {}`",
                    params_hint(m),
                    letters[0],
                    letters[1]
                ))
            } else {
                d.help(format!(
                    "declare it with `module {name}{};` to make it one module",
                    params_hint(m)
                ))
            };
            self.diags.push(d);
        } else if rule.cond.is_some() && looks_like_label(name) {
            self.diags.push(
                Diagnostic::error(
                    Code::UndeclaredModule,
                    format!("module `{name}` is not declared"),
                )
                .primary(
                    m.name_span,
                    "read as the predecessor, and what follows `:` as its condition",
                )
                .help(format!(
                    "a rule label is written glued to its colon: `{name}: …`"
                )),
            );
        } else if self.reported.insert(name.clone()) {
            self.diags.push(undeclared(name, m));
        }
    }

    fn report_undeclared(&mut self, m: &Module) {
        if let ModName::Name(n) = &m.name
            && !self.scope.declares(n)
            && !is_letter(n)
            && !is_builtin(n)
            && !splits(n)
            && self.reported.insert(n.clone())
        {
            self.diags.push(undeclared(n, m));
        }
    }

    fn split_list(&mut self, ms: &mut Vec<Module>) {
        let scope = self.scope;
        if !ms.iter().any(|m| needs_split(m, scope)) {
            for m in ms.iter() {
                self.report_undeclared(m);
            }
            return;
        }
        let old = std::mem::take(ms);
        for m in old {
            if !needs_split(&m, scope) {
                self.report_undeclared(&m);
                ms.push(m);
                continue;
            }
            let ModName::Name(name) = &m.name else {
                unreachable!("needs_split only accepts names")
            };
            if word_like(name) || (m.args.is_some() && lower_word(name)) {
                let spaced: Vec<String> = name.chars().map(String::from).collect();
                self.diags.push(
                    Diagnostic::warning(
                        Code::SplitWord,
                        format!("`{name}` is read as {} single-letter modules", spaced.len()),
                    )
                    .primary(m.name_span, format!("read as {}", spaced.join(" ")))
                    .help(format!(
                        "declare `module {name}{};` if you meant one module; write `{}` to keep the letters and silence this",
                        params_hint(&m),
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
}

/// `(a, b)` for a module written with two parameters, `` for none.
fn params_hint(m: &Module) -> String {
    match m.arity() {
        0 => String::new(),
        n => format!(
            "({})",
            (0..n)
                .map(|i| format!("p{i}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// `r2`, `p1`: letters then digits, the shape of a rule label.
fn looks_like_label(name: &str) -> bool {
    let letters = name.chars().take_while(|c| c.is_ascii_lowercase()).count();
    letters > 0 && letters < name.len() && name[letters..].chars().all(|c| c.is_ascii_digit())
}

fn undeclared(name: &str, m: &Module) -> Diagnostic {
    let d = Diagnostic::error(
        Code::UndeclaredModule,
        format!("module `{name}` is not declared"),
    )
    .primary(m.name_span, "multi-letter names must be declared");
    let letters: String = name.chars().take_while(|c| c.is_alphabetic()).collect();
    let digits: String = name[letters.len()..].to_string();
    let digit_runs = name.chars().filter(char::is_ascii_digit).count();
    let mixed = digits.chars().any(|c| c.is_alphabetic());
    if digit_runs > 0 && mixed {
        d.help(format!(
            "digits are numbers in lsyc, not module names, so `{name}` is one name: write subscripted letters as letters (`F1` → `A`, with `interpret A -> F;`), or declare `module {letters}{};` and write the modules apart",
            digits.chars().take_while(char::is_ascii_digit).collect::<String>()
        ))
    } else if !letters.is_empty()
        && !digits.is_empty()
        && digits.chars().all(|c| c.is_ascii_digit())
        && m.args.is_none()
    {
        d.help(format!(
            "declare it with `module {name};`, or if you meant a parameter write `{letters}({digits})`"
        ))
    } else {
        d.help(format!(
            "declare it with `module {name}{};` at the top of the file or in the lsystem",
            params_hint(m)
        ))
    }
}

fn word_like(name: &str) -> bool {
    let mut cs = name.chars();
    let first = cs.next();
    name.chars().count() >= 3 && first.is_some_and(char::is_uppercase) && cs.all(char::is_lowercase)
}

/// `leaf`, `apex`: a lowercase word of three letters or more, not one letter
/// repeated (`fff`).
fn lower_word(name: &str) -> bool {
    let mut cs = name.chars();
    let first = cs.next();
    name.chars().count() >= 3
        && name.chars().all(char::is_lowercase)
        && name.chars().any(|c| Some(c) != first)
}

fn needs_split(m: &Module, scope: &Scope) -> bool {
    match &m.name {
        ModName::Name(n) => !scope.declares(n) && !is_letter(n) && !is_builtin(n) && splits(n),
        _ => false,
    }
}
