//! LALRPOP glue: runs the lexer and the generated parser, turns recovered syntax
//! errors into diagnostics a person can read, then attaches comments and resolves
//! module names.
//!
//! Owns: `parse`, the one entry point from text to `ast::File`. Must not check
//! meaning beyond the syntax (that is `check`).

use crate::ast::{BinOp, Expr, ExprKind, File, Ident, UnOp};
use crate::diagnostic::{Code, Diagnostic};
use crate::lexer::{self, LexError, Token};
use crate::span::{LineIndex, Span};
use crate::{resolve, trivia};
use lalrpop_util::{ErrorRecovery, ParseError};

lalrpop_util::lalrpop_mod!(
    #[allow(clippy::all, clippy::pedantic, unused_parens, dead_code)]
    grammar,
    "/lsy.rs"
);

/// The deepest expression the parser builds; deeper ones are an error.
pub const MAX_EXPR_DEPTH: u32 = 200;

/// An expression under construction and its depth.
pub type D = (Expr, u32);

pub fn sp(l: usize, r: usize) -> Span {
    Span::new(l, r)
}

/// `&&` or `||` in a module string: two modules, the parameters on the second.
pub fn doubled(
    c: char,
    l: usize,
    r: usize,
    args: Option<Vec<Expr>>,
    end: usize,
) -> Vec<crate::ast::Module> {
    use crate::ast::{ModName, Module};
    let mid = l + 1;
    vec![
        Module {
            name: ModName::Symbol(c),
            name_span: Span::new(l, mid),
            args: None,
            span: Span::new(l, mid),
        },
        Module {
            name: ModName::Symbol(c),
            name_span: Span::new(mid, r),
            args,
            span: Span::new(mid, end),
        },
    ]
}

/// State the grammar actions write to.
#[derive(Default)]
pub struct ParseState {
    pub recovered: Vec<ErrorRecovery<usize, Token, LexError>>,
    pub diags: Vec<Diagnostic>,
}

impl ParseState {
    fn guard(&mut self, kind: ExprKind, depth: u32, span: Span, children_ok: bool) -> D {
        if depth > MAX_EXPR_DEPTH {
            if children_ok {
                self.diags.push(
                    Diagnostic::error(Code::TooDeep, "expression is nested too deeply")
                        .primary(span, format!("more than {MAX_EXPR_DEPTH} levels deep"))
                        .help("split it into named constants or simpler expressions"),
                );
            }
            return (
                Expr {
                    kind: ExprKind::Error,
                    span,
                },
                depth,
            );
        }
        (Expr { kind, span }, depth)
    }

    pub fn binary(&mut self, op: BinOp, a: D, b: D, span: Span) -> D {
        let ok = a.1 <= MAX_EXPR_DEPTH && b.1 <= MAX_EXPR_DEPTH;
        let depth = a.1.max(b.1) + 1;
        self.guard(
            ExprKind::Binary(op, Box::new(a.0), Box::new(b.0)),
            depth,
            span,
            ok,
        )
    }

    pub fn unary(&mut self, op: UnOp, a: D, span: Span) -> D {
        let ok = a.1 <= MAX_EXPR_DEPTH;
        let depth = a.1 + 1;
        self.guard(ExprKind::Unary(op, Box::new(a.0)), depth, span, ok)
    }

    pub fn call(&mut self, f: Ident, args: Vec<D>, span: Span) -> D {
        let ok = args.iter().all(|a| a.1 <= MAX_EXPR_DEPTH);
        let depth = args.iter().map(|a| a.1).max().unwrap_or(0) + 1;
        let args = args.into_iter().map(|a| a.0).collect();
        self.guard(ExprKind::Call(f, args), depth, span, ok)
    }
}

/// The result of parsing: a tree (possibly with `Error` nodes) and diagnostics.
pub struct Parsed {
    pub file: File,
    pub diagnostics: Vec<Diagnostic>,
}

/// Parses a source text. Always returns a tree; every problem found is a diagnostic.
pub fn parse(source: &str) -> Parsed {
    let lexed = lexer::lex(source);
    let mut diagnostics = lexed.diagnostics;
    let mut state = ParseState::default();
    let tokens = lexed.tokens.clone();
    let result = grammar::FileParser::new()
        .parse(&mut state, lexed.tokens.into_iter().map(Ok::<_, LexError>));
    let index = LineIndex::new(source);
    let end_word = end_word(&tokens);
    let mut syntax = Vec::new();
    for rec in state.recovered.drain(..) {
        syntax.push(syntax_error(
            rec.error,
            &tokens,
            &lexed.comments,
            source,
            &index,
            end_word,
        ));
    }
    let mut file = match result {
        Ok(file) => file,
        Err(e) => {
            syntax.push(syntax_error(
                e,
                &tokens,
                &lexed.comments,
                source,
                &index,
                end_word,
            ));
            File::default()
        }
    };
    // One error per place: recovery can report the same token twice.
    syntax.dedup_by(|a, b| a.position() == b.position());
    // A comment or string that runs to the end of the file explains the end.
    if diagnostics
        .iter()
        .any(|d| matches!(d.code, Code::UnterminatedComment))
    {
        syntax.retain(|d| d.code != Code::UnexpectedEof);
    }
    diagnostics.extend(syntax);
    diagnostics.append(&mut state.diags);
    trivia::attach(&mut file, lexed.comments, source);
    resolve::resolve(&mut file, &mut diagnostics);
    crate::diagnostic::sort(&mut diagnostics);
    Parsed { file, diagnostics }
}

/// Parses bytes that may not be UTF-8. Invalid UTF-8 is reported at the first bad
/// byte; the rest is parsed from the lossy text so that later errors still show.
pub fn decode(bytes: &[u8]) -> (String, Option<Diagnostic>) {
    match std::str::from_utf8(bytes) {
        Ok(s) => (s.to_string(), None),
        Err(e) => {
            let at = e.valid_up_to();
            let text = String::from_utf8_lossy(bytes).into_owned();
            // The lossy text has U+FFFD (3 bytes) where the bad bytes were; the
            // prefix up to `at` is identical in both.
            let d = Diagnostic::error(Code::InvalidUtf8, "the file is not valid UTF-8")
                .primary(Span::new(at, at + 3), "invalid byte sequence here")
                .help("save the file as UTF-8");
            (text, Some(d))
        }
    }
}

fn describe_expected(expected: &[String]) -> Vec<String> {
    const MODULE_STARTS: &[&str] = &[
        "\"name\"",
        "\"query\"",
        "\"cut\"",
        "\"+\"",
        "\"-\"",
        "\"&\"",
        "\"^\"",
        "\"\\\\\"",
        "\"/\"",
        "\"|\"",
        "\"$\"",
        "\"*\"",
        "\"[\"",
        "\"]\"",
        "\"{\"",
        "\".\"",
        "\"!\"",
        "\"'\"",
        "\"%\"",
        "\"&&\"",
        "\"||\"",
    ];
    const EXPR_STARTS: &[&str] = &[
        "\"number\"",
        "\"name\"",
        "\"true\"",
        "\"false\"",
        "\"(\"",
        "\"-\"",
        "\"!\"",
    ];
    const OPERATORS: &[&str] = &[
        "\"+\"", "\"-\"", "\"*\"", "\"/\"", "\"%\"", "\"^\"", "\"==\"", "\"!=\"", "\"<\"",
        "\"<=\"", "\">\"", "\">=\"", "\"&&\"", "\"||\"",
    ];
    const STATEMENT_STARTS: &[&str] = &[
        "\"angle\"",
        "\"derive\"",
        "\"step\"",
        "\"axiom\"",
        "\"ignore\"",
        "\"module\"",
        "\"interpret\"",
        "\"label\"",
    ];
    let has = |set: &[&str]| set.iter().all(|t| expected.iter().any(|e| e == t));
    // Most of the module symbols (some are left out where a rule starts).
    let has_modules = MODULE_STARTS
        .iter()
        .filter(|t| expected.iter().any(|e| e == *t))
        .count()
        >= 12;
    let mut rest: Vec<&String> = expected.iter().collect();
    let mut out = Vec::new();
    let mut take = |set: &[&str], phrase: &str, rest: &mut Vec<&String>| {
        rest.retain(|e| !set.contains(&e.as_str()));
        out.push(phrase.to_string());
    };
    if has(STATEMENT_STARTS) {
        take(
            STATEMENT_STARTS,
            "a statement (`axiom …;`, a rule, …)",
            &mut rest,
        );
        rest.retain(|e| {
            !MODULE_STARTS.contains(&e.as_str())
                && !matches!(e.as_str(), "\"tropism\"" | "\"consider\"" | "\"decompose\"")
        });
    } else if has_modules {
        take(MODULE_STARTS, "a module", &mut rest);
        // `tropism(e)` is a module too.
        rest.retain(|e| e.as_str() != "\"tropism\"");
    }
    if has(EXPR_STARTS) {
        take(EXPR_STARTS, "an expression", &mut rest);
    }
    if has(OPERATORS) {
        take(OPERATORS, "an operator", &mut rest);
    }
    for e in rest {
        let phrase = match e.as_str() {
            "\"name\"" => "a name".to_string(),
            "\"label\"" => "a rule label".to_string(),
            "\"query\"" => "a query module".to_string(),
            "\"number\"" => "a number".to_string(),
            "\"string\"" => "a string".to_string(),
            other => {
                let inner = other.trim_matches('"').replace("\\\\", "\\");
                format!("`{inner}`")
            }
        };
        if !out.contains(&phrase) {
            out.push(phrase);
        }
    }
    out
}

fn list(items: &[String]) -> String {
    match items {
        [] => "something else".to_string(),
        [one] => one.clone(),
        [a, b] => format!("{a} or {b}"),
        _ => format!("one of {}", items.join(", ")),
    }
}

/// Where a `;` was probably forgotten: the token at `at` (or the first token of
/// its line) starts a line, and the token before it ends an earlier line without `;`.
fn missing_semicolon(
    tokens: &[(usize, Token, usize)],
    at: usize,
    index: &LineIndex,
) -> Option<usize> {
    let line = index.line(at);
    // The first token on the unexpected token's line (a search: one long
    // line can hold an error per token).
    let line_start = index.line_start(line);
    let first = tokens.partition_point(|t| t.0 < line_start);
    let prev = tokens.get(first.checked_sub(1)?)?;
    let ends_statement = matches!(prev.1, Token::Semi | Token::LBrace | Token::RBrace);
    (!ends_statement && index.line(prev.2) < line).then_some(prev.2)
}

/// Where cpfg's or L-Py's `endlsystem` (or `endgroup`) first appears, if
/// anywhere: every syntax error of the file mentions it.
fn end_word(tokens: &[(usize, Token, usize)]) -> Option<Span> {
    tokens
        .iter()
        .find(|t| matches!(&t.1, Token::Ident(w) if w == "endlsystem" || w == "endgroup"))
        .map(|t| Span::new(t.0, t.2))
}

fn syntax_error(
    e: ParseError<usize, Token, LexError>,
    tokens: &[(usize, Token, usize)],
    comments: &[lexer::Comment],
    source: &str,
    index: &LineIndex,
    end_word: Option<Span>,
) -> Diagnostic {
    let d = syntax_error_at(e, tokens, source, index);
    explain_context(d, tokens, comments, source, index, end_word)
}

/// Adds notes for the usual traps near a syntax error: `//` glued to modules
/// (a comment, not two rolls) and `name:` (a label, not a condition).
fn explain_context(
    mut d: Diagnostic,
    tokens: &[(usize, Token, usize)],
    comments: &[lexer::Comment],
    source: &str,
    index: &LineIndex,
    end_word: Option<Span>,
) -> Diagnostic {
    let at = d.position() as usize;
    let line = index.line(at);
    let near = |pos: usize| {
        let l = index.line(pos);
        l == line || l + 1 == line
    };
    for c in comments {
        let start = c.span.start as usize;
        let glued = start > 0
            && source[..start]
                .chars()
                .next_back()
                .is_some_and(|ch| !ch.is_whitespace() && ch != ';');
        if c.text.starts_with("//") && glued && near(start) {
            d = d
                .secondary(Span::new(start, start + 2), "this `//` starts a comment")
                .note("`//` always starts a comment; two rolls are written `/ /`");
            break;
        }
    }
    // A label on this statement: `A: x > 2 -> …` reads `A:` as a label.
    let pos = tokens.partition_point(|t| t.0 < at);
    for t in tokens[..pos].iter().rev() {
        if matches!(t.1, Token::Semi | Token::LBrace) {
            break;
        }
        if let Token::Label(name) = &t.1 {
            let label = Span::new(t.0, t.2);
            d = match name.as_str() {
                "ω" | "omega" | "axiom" | "Axiom" => d
                    .note(format!("`{name}:` is read as a rule label"))
                    .help("the axiom is a statement: `axiom F;`")
                    .fix("write `axiom`", label, "axiom"),
                "ignore" | "consider" => d
                    .note(format!("`{name}:` is read as a rule label"))
                    .help(format!("`{name}` takes the modules without a colon: `{name} + - F;`"))
                    .fix(format!("write `{name}`"), label, name.as_str()),
                _ => d.note(format!(
                    "`{name}:` is read as a rule label; for a condition write a space before the colon: `{name} : …`"
                )),
            };
            break;
        }
    }
    // cpfg and L-Py close an lsystem with a word; lsyc with `}`.
    if let Some(word) = end_word {
        d = d
            .secondary(word, "cpfg's and L-Py's end of an lsystem")
            .help("an lsyc lsystem ends with its closing `}`: remove `endlsystem`")
            .fix("remove it", word, "");
    }
    d
}

fn syntax_error_at(
    e: ParseError<usize, Token, LexError>,
    tokens: &[(usize, Token, usize)],
    source: &str,
    index: &LineIndex,
) -> Diagnostic {
    match e {
        ParseError::UnrecognizedToken {
            token: (l, tok, r),
            expected,
        } => {
            let wanted = describe_expected(&expected);
            let span = Span::new(l, r);
            let mut d = Diagnostic::error(
                Code::UnexpectedToken,
                format!("expected {}, found {tok}", list(&wanted)),
            )
            .primary(span, format!("unexpected {tok}"));
            // A missing `;` shows up on a later line: point at the end of the line
            // before the statement that swallowed the next one.
            let semi = expected.iter().any(|e| e == "\";\"");
            if semi && let Some(pend) = missing_semicolon(tokens, l, index) {
                d = d
                    .secondary(Span::new(pend, pend), "`;` may be missing here")
                    .help("end each statement with `;`")
                    .fix("insert `;`", Span::new(pend, pend), ";");
            }
            if tok.is_keyword()
                && expected.iter().any(|e| e == "\"name\"")
                && !wanted.iter().any(|w| w == "a module")
            {
                d = d.note(format!(
                    "{tok} is a keyword of the language and cannot be used as a name"
                ));
            }
            // Tokens are in source order: the ones before `l` end at `before`
            // (a search, not a scan: a file can have an error per token).
            let before = tokens.partition_point(|t| t.0 < l);
            let in_condition = tokens[..before]
                .iter()
                .rev()
                .take_while(|t| !matches!(t.1, Token::Semi | Token::LBrace | Token::RBrace))
                .any(|t| t.1 == Token::Colon);
            if tok == Token::Assign && !in_condition && expected.iter().any(|e| e == "\"->\"") {
                // `X = F[+X]`: the rule arrow of many web L-system tools; `X => F`.
                let after = tokens.partition_point(|t| t.0 < r);
                let arrow = match tokens.get(after).filter(|t| t.0 == r) {
                    Some(gt) if gt.1 == Token::Gt => Span::new(l, gt.2),
                    _ => span,
                };
                d = d
                    .help("a rule is written `X -> …`; `=` only defines a constant")
                    .fix("replace with `->`", arrow, "->");
            } else if tok == Token::Assign {
                d = d
                    .help("to compare, write `==`; `=` only defines a constant")
                    .fix("replace with `==`", span, "==");
            }
            if tok == Token::Star
                && let Some(colon) = tokens[..before].last().filter(|t| t.1 == Token::Colon)
            {
                d = d
                    .help(
                        "`: *` is cpfg's \"no condition\"; in lsyc leave the condition out: `A -> …`",
                    )
                    .fix("remove `: *`", Span::new(colon.0, r), "");
            }
            if matches!(tok, Token::Label(_)) {
                d = d.note("a name followed directly by `:` is a rule label; write a space before `:` for a condition");
            }
            d
        }
        ParseError::UnrecognizedEof { location, expected } => {
            let wanted = describe_expected(&expected);
            let at = location.min(source.len());
            let mut d = Diagnostic::error(
                Code::UnexpectedEof,
                format!("unexpected end of file, expected {}", list(&wanted)),
            )
            .primary(Span::new(at, at), "the file ends here");
            // `F -> F+F` then `}`: the `}` was read as a module of the successor.
            if expected.iter().any(|e| e == "\";\"")
                && let Some(close) = tokens.iter().rev().find(|t| t.1 == Token::RBrace)
                && let Some(pend) = missing_semicolon(tokens, close.0, index)
            {
                d = d
                    .secondary(Span::new(pend, pend), "`;` may be missing here")
                    .secondary(
                        Span::new(close.0, close.2),
                        "so this `}` was read as part of the successor",
                    )
                    .note("inside a successor `}` closes a polygon `{`")
                    .help("end each statement with `;`")
                    .fix("insert `;`", Span::new(pend, pend), ";");
            }
            d
        }
        ParseError::ExtraToken { token: (l, tok, r) } => {
            Diagnostic::error(Code::UnexpectedToken, format!("unexpected {tok}"))
                .primary(Span::new(l, r), "not expected here")
        }
        ParseError::InvalidToken { location } => {
            Diagnostic::error(Code::UnexpectedChar, "invalid token")
                .primary(Span::new(location, location + 1), "here")
        }
        ParseError::User { error } => {
            Diagnostic::error(Code::UnexpectedChar, format!("invalid token: {error:?}"))
        }
    }
}
