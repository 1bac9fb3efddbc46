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
    let result = grammar::FileParser::new().parse(
        &mut state,
        lexed.tokens.into_iter().map(Ok::<_, LexError>),
    );
    let index = LineIndex::new(source);
    let mut syntax = Vec::new();
    for rec in state.recovered.drain(..) {
        syntax.push(syntax_error(rec.error, &tokens, source, &index));
    }
    let mut file = match result {
        Ok(file) => file,
        Err(e) => {
            syntax.push(syntax_error(e, &tokens, source, &index));
            File::default()
        }
    };
    // One error per place: recovery can report the same token twice.
    syntax.dedup_by(|a, b| a.position() == b.position());
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
        "\"name\"", "\"query\"", "\"cut\"", "\"+\"", "\"-\"", "\"&\"", "\"^\"", "\"\\\\\"",
        "\"/\"", "\"|\"", "\"$\"", "\"*\"", "\"[\"", "\"]\"", "\"{\"", "\".\"", "\"!\"",
        "\"'\"", "\"%\"",
    ];
    const EXPR_STARTS: &[&str] = &[
        "\"number\"", "\"name\"", "\"true\"", "\"false\"", "\"(\"", "\"-\"", "\"!\"",
    ];
    const OPERATORS: &[&str] = &[
        "\"+\"", "\"-\"", "\"*\"", "\"/\"", "\"%\"", "\"^\"", "\"==\"", "\"!=\"", "\"<\"",
        "\"<=\"", "\">\"", "\">=\"", "\"&&\"", "\"||\"",
    ];
    let has = |set: &[&str]| set.iter().all(|t| expected.iter().any(|e| e == t));
    let mut rest: Vec<&String> = expected.iter().collect();
    let mut out = Vec::new();
    let mut take = |set: &[&str], phrase: &str, rest: &mut Vec<&String>| {
        rest.retain(|e| !set.contains(&e.as_str()));
        out.push(phrase.to_string());
    };
    if has(MODULE_STARTS) {
        take(MODULE_STARTS, "a module", &mut rest);
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
fn missing_semicolon(tokens: &[(usize, Token, usize)], at: usize, index: &LineIndex) -> Option<usize> {
    let pos = tokens.partition_point(|t| t.0 < at);
    let line = index.line(at);
    // The first token on the unexpected token's line.
    let mut first = pos;
    while first > 0 && index.line(tokens[first - 1].0) == line {
        first -= 1;
    }
    let prev = tokens.get(first.checked_sub(1)?)?;
    let ends_statement = matches!(prev.1, Token::Semi | Token::LBrace | Token::RBrace);
    (!ends_statement && index.line(prev.2) < line).then_some(prev.2)
}

fn syntax_error(
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
            if semi {
                if let Some(pend) = missing_semicolon(tokens, l, index) {
                    d = d
                        .secondary(Span::new(pend, pend), "`;` may be missing here")
                        .help("end each statement with `;`");
                }
            }
            if tok.is_keyword()
                && expected.iter().any(|e| e == "\"name\"")
                && !wanted.iter().any(|w| w == "a module")
            {
                d = d.note(format!(
                    "{tok} is a keyword of the language and cannot be used as a name"
                ));
            }
            if matches!(tok, Token::Label(_)) {
                d = d.note("a name followed directly by `:` is a rule label; write a space before `:` for a condition");
            }
            d
        }
        ParseError::UnrecognizedEof { location, expected } => {
            let wanted = describe_expected(&expected);
            let at = location.min(source.len());
            Diagnostic::error(
                Code::UnexpectedEof,
                format!("unexpected end of file, expected {}", list(&wanted)),
            )
            .primary(Span::new(at, at), "the file ends here")
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
