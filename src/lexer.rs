//! The lexer: source text to `(start, Token, end)` triples, comments kept aside.
//!
//! Owns: the token set of the language (logos), comments as trivia for the
//! formatter, and lexical diagnostics (bad bytes, stray characters, unterminated
//! comments and strings, numbers out of range). Must not decide what tokens mean
//! together; that is the grammar's job.

use crate::diagnostic::{Code, Diagnostic};
use crate::span::Span;
use logos::Logos;
use std::fmt;

/// What went wrong inside one token, reported by the logos callbacks.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum LexError {
    #[default]
    Unexpected,
    UnterminatedComment,
    UnterminatedString,
    /// The escape's start and end: `\` and the character after it, whole.
    InvalidEscape(usize, usize),
    NumberOutOfRange,
}

#[derive(Logos, Clone, Debug, PartialEq)]
#[logos(error = LexError)]
#[logos(skip r"[ \t\r\n\f\u{feff}]+")]
pub enum Token {
    // Items and statements.
    #[token("lsystem")]
    Lsystem,
    #[token("module")]
    Module,
    #[token("const")]
    Const,
    #[token("element")]
    Element,
    #[token("palette")]
    Palette,
    #[token("scene")]
    Scene,
    #[token("guide")]
    Guide,
    #[token("link")]
    Link,
    #[token("polygon")]
    Polygon,
    #[token("system")]
    System,
    #[token("seed")]
    Seed,
    #[token("heading")]
    Heading,
    #[token("tokens")]
    Tokens,
    #[token("edge")]
    Edge,
    #[token("with")]
    With,
    #[token("angle")]
    Angle,
    #[token("derive")]
    Derive,
    #[token("step")]
    Step,
    #[token("axiom")]
    Axiom,
    #[token("ignore")]
    Ignore,
    #[token("interpret")]
    Interpret,
    #[token("cut")]
    Cut,
    #[token("tropism")]
    Tropism,
    #[token("consider")]
    Consider,
    #[token("decompose")]
    Decompose,
    #[token("true")]
    True,
    #[token("false")]
    False,
    #[token("ε")]
    Epsilon,

    /// A name: module run, parameter, constant, function, item name.
    #[regex(r"[\p{L}_][\p{L}\p{N}_]*", |lex| lex.slice().to_string())]
    Ident(String),
    /// `name:` written without a space: a rule label.
    #[regex(r"[\p{L}_][\p{L}\p{N}_]*:", |lex| { let s = lex.slice(); s[..s.len() - 1].to_string() })]
    Label(String),
    /// `?X`, `?D_L`: a query module.
    #[regex(r"\?[\p{L}_][\p{L}\p{N}_]*", |lex| lex.slice().to_string())]
    Query(String),
    #[regex(r"[0-9]+(\.[0-9]*)?([eE][+-]?[0-9]+)?", number)]
    #[regex(r"\.[0-9]+([eE][+-]?[0-9]+)?", number)]
    Number(f64),
    #[token("\"", string)]
    Str(String),

    #[token("->")]
    Arrow,
    #[token("<=")]
    Le,
    #[token(">=")]
    Ge,
    #[token("==")]
    EqEq,
    #[token("!=")]
    Ne,
    #[token("&&")]
    AndAnd,
    #[token("||")]
    OrOr,
    #[token("<")]
    Lt,
    #[token(">")]
    Gt,
    #[token("=")]
    Assign,
    #[token(":")]
    Colon,
    #[token(";")]
    Semi,
    #[token(",")]
    Comma,
    #[token("(")]
    LParen,
    #[token(")")]
    RParen,
    #[token("[")]
    LBracket,
    #[token("]")]
    RBracket,
    #[token("{")]
    LBrace,
    #[token("}")]
    RBrace,
    #[token("+")]
    Plus,
    #[token("-")]
    Minus,
    #[token("*")]
    Star,
    #[token("/")]
    Slash,
    #[token("\\")]
    Backslash,
    #[token("^")]
    Caret,
    #[token("&")]
    Amp,
    #[token("|")]
    Pipe,
    #[token("$")]
    Dollar,
    #[token(".")]
    Dot,
    #[token("!")]
    Bang,
    #[token("'")]
    Quote,
    #[token("%")]
    Percent,

    #[regex(r"//[^\r\n]*", |lex| lex.slice().to_string(), allow_greedy = true)]
    LineComment(String),
    #[token("/*", block_comment)]
    BlockComment(String),
}

fn number(lex: &mut logos::Lexer<Token>) -> Result<f64, LexError> {
    match lex.slice().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(LexError::NumberOutOfRange),
    }
}

fn block_comment(lex: &mut logos::Lexer<Token>) -> Result<String, LexError> {
    let rest = lex.remainder();
    match rest.find("*/") {
        Some(i) => {
            lex.bump(i + 2);
            Ok(lex.slice().to_string())
        }
        None => {
            lex.bump(rest.len());
            Err(LexError::UnterminatedComment)
        }
    }
}

fn string(lex: &mut logos::Lexer<Token>) -> Result<String, LexError> {
    let rest = lex.remainder();
    let mut out = String::new();
    let mut chars = rest.char_indices();
    while let Some((i, c)) = chars.next() {
        match c {
            '"' => {
                lex.bump(i + 1);
                return Ok(out);
            }
            '\n' => break,
            '\\' => match chars.next() {
                Some((_, '"')) => out.push('"'),
                Some((_, '\\')) => out.push('\\'),
                Some((_, 'n')) => out.push('\n'),
                Some((_, 't')) => out.push('\t'),
                Some((j, escaped)) => {
                    let at = lex.span().end + i;
                    let end = at + 1 + escaped.len_utf8();
                    lex.bump(j);
                    // Skip to the closing quote so one bad escape is one error.
                    let tail = lex.remainder();
                    let stop = tail
                        .find(['"', '\n'])
                        .map_or(tail.len(), |k| k + usize::from(tail[k..].starts_with('"')));
                    lex.bump(stop);
                    return Err(LexError::InvalidEscape(at, end));
                }
                None => break,
            },
            _ => out.push(c),
        }
    }
    // The string runs to the end of its line; a `;` there most likely ends the
    // statement, so it is left for the parser.
    let line_end = rest.find('\n').unwrap_or(rest.len());
    let line = rest[..line_end].trim_end();
    let stop = if line.ends_with(';') {
        line.len() - 1
    } else {
        line_end
    };
    lex.bump(stop);
    Err(LexError::UnterminatedString)
}

/// A comment kept as trivia, with its delimiters.
#[derive(Clone, Debug, PartialEq)]
pub struct Comment {
    pub text: String,
    pub span: Span,
}

/// The result of lexing one file.
pub struct Lexed {
    pub tokens: Vec<(usize, Token, usize)>,
    pub comments: Vec<Comment>,
    pub diagnostics: Vec<Diagnostic>,
}

/// Lexes a whole source text. Never fails: problems become diagnostics and the
/// offending text is left out of the token stream.
pub fn lex(source: &str) -> Lexed {
    let mut tokens = Vec::new();
    let mut comments = Vec::new();
    let mut diagnostics = Vec::new();
    let mut lexer = Token::lexer(source);
    // Runs of stray characters are reported once.
    let mut stray: Option<(usize, usize)> = None;
    let flush_stray = |stray: &mut Option<(usize, usize)>, diagnostics: &mut Vec<Diagnostic>| {
        if let Some((s, e)) = stray.take() {
            diagnostics.push(stray_diagnostic(source, s, e));
        }
    };
    while let Some(result) = lexer.next() {
        let range = lexer.span();
        let span = Span::new(range.start, range.end);
        match result {
            Ok(tok) => {
                flush_stray(&mut stray, &mut diagnostics);
                match tok {
                    Token::LineComment(text) | Token::BlockComment(text) => {
                        comments.push(Comment { text, span })
                    }
                    tok => tokens.push((range.start, tok, range.end)),
                }
            }
            Err(LexError::Unexpected) => {
                let text = &source[range.clone()];
                if text == "→" {
                    // Reported, then read as the arrow it stands for.
                    flush_stray(&mut stray, &mut diagnostics);
                    diagnostics.push(stray_diagnostic(source, range.start, range.end));
                    tokens.push((range.start, Token::Arrow, range.end));
                    continue;
                }
                let is_nul = text.contains('\0');
                if is_nul {
                    flush_stray(&mut stray, &mut diagnostics);
                    diagnostics.push(
                        Diagnostic::error(Code::NulByte, "the source contains a NUL byte")
                            .primary(span, "NUL byte here")
                            .help("remove it; .lsy files are plain UTF-8 text"),
                    );
                    continue;
                }
                stray = match stray {
                    Some((s, e)) if e == range.start => Some((s, range.end)),
                    other => {
                        let mut other = other;
                        flush_stray(&mut other, &mut diagnostics);
                        Some((range.start, range.end))
                    }
                };
            }
            Err(e) => {
                flush_stray(&mut stray, &mut diagnostics);
                // Keep a stand-in token so that the parser does not trip over the gap.
                let stand_in = match e {
                    LexError::UnterminatedString | LexError::InvalidEscape(..) => {
                        Some(Token::Str(String::new()))
                    }
                    LexError::NumberOutOfRange => Some(Token::Number(0.0)),
                    _ => None,
                };
                if let Some(t) = stand_in {
                    tokens.push((range.start, t, range.end));
                }
                diagnostics.push(token_error(e, span));
            }
        }
    }
    flush_stray(&mut stray, &mut diagnostics);
    Lexed {
        tokens,
        comments,
        diagnostics,
    }
}

fn stray_diagnostic(source: &str, start: usize, end: usize) -> Diagnostic {
    let text = &source[start..end];
    let first = text.chars().next().unwrap_or(' ');
    let what = if text.chars().count() == 1 {
        format!("unexpected character `{}`", first.escape_debug())
    } else {
        format!("unexpected characters `{}`", text.escape_debug())
    };
    let mut d = Diagnostic::error(Code::UnexpectedChar, what).primary(
        Span::new(start, end),
        "no token of the language starts here",
    );
    let after = &source[end..];
    // `#define N 5` and `#ignore: + -` to the end of the line, rewritten.
    let line = &after[..after.find('\n').unwrap_or(after.len())];
    let to_eol = Span::new(start, end + line.len());
    let port = |word: &str| {
        let rest = line.strip_prefix(word)?.trim();
        let rest = rest.strip_suffix(';').unwrap_or(rest).trim();
        (!rest.is_empty() && !rest.contains("//") && !rest.contains("/*")).then_some(rest)
    };
    if text == "#" {
        if let Some((name, value)) = port("define").and_then(|r| r.split_once(char::is_whitespace))
            && matches!(&lex(name).tokens[..], [(_, Token::Ident(n), _)] if n == name)
        {
            d = d.fix(
                "write it as a constant",
                to_eol,
                format!("const {name} = {};", value.trim()),
            );
        }
        for word in ["ignore", "consider"] {
            if let Some(list) = port(word).map(|r| r.strip_prefix(':').unwrap_or(r).trim())
                && !list.is_empty()
            {
                d = d.fix(
                    format!("write `{word} …;`"),
                    to_eol,
                    format!("{word} {list};"),
                );
            }
        }
    }
    d = match first {
        '#' if after.starts_with("define") => d.help(
            "cpfg's `#define N 5` is a constant in lsyc: `const N = 5;` (before the lsystem; `-D N=…` overrides it)",
        ),
        '#' if after.starts_with("ignore") => {
            d.help("cpfg's `#ignore: + -` is a statement in the lsystem: `ignore + -;`")
        }
        '#' if after.starts_with("consider") => {
            d.help("cpfg's `#consider: A B` is a statement in the lsystem: `consider A B;`")
        }
        '#' if after.starts_with("include") => {
            d.help("lsyc has no `#include`: a program is one file")
        }
        '#' => d.help("lsyc sets the line width with `!(w)`; `#` is cpfg's width symbol"),
        '@' => d.help(
            "cpfg's `@` commands are not part of lsyc; see the turtle table in docs/language.md",
        ),
        '~' => d.help("surfaces are drawn by declared `element` items, not `~`"),
        '?' => d.help("a query module is written `?` followed directly by its name, as in `?X(d)`"),
        '"' => d.help("strings are written in double quotes: \"…\""),
        '→' if text == "→" => d
            .help("write the arrow as `->`")
            .fix("replace with `->`", Span::new(start, end), "->"),
        '→' => d.help("write the arrow as `->`"),
        _ => d,
    };
    d
}

fn token_error(e: LexError, span: Span) -> Diagnostic {
    match e {
        LexError::UnterminatedComment => {
            Diagnostic::error(Code::UnterminatedComment, "block comment is never closed")
                .primary(
                    Span::new(span.start as usize, span.start as usize + 2),
                    "comment starts here",
                )
                .help("close it with `*/`")
        }
        LexError::UnterminatedString => {
            Diagnostic::error(Code::UnterminatedString, "string is never closed")
                .primary(span, "this string has no closing `\"` on its line")
                .help("add `\"` at the end of the string")
        }
        LexError::InvalidEscape(at, end) => {
            Diagnostic::error(Code::InvalidEscape, "unknown escape sequence in string")
                .primary(Span::new(at, end), "not an escape lsyc knows")
                .help("the escapes are \\\" \\\\ \\n \\t")
        }
        LexError::NumberOutOfRange => {
            Diagnostic::error(Code::NumberOutOfRange, "number is too large to represent")
                .primary(span, "this literal overflows a 64-bit float")
                .help("numbers must be below about 1.8e308")
        }
        LexError::Unexpected => Diagnostic::error(Code::UnexpectedChar, "unexpected character")
            .primary(span, "no token of the language starts here"),
    }
}

impl fmt::Display for Token {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Token::Ident(s) => write!(f, "name `{s}`"),
            Token::Label(s) => write!(f, "label `{s}:`"),
            Token::Query(s) => write!(f, "query module `{s}`"),
            Token::Number(n) => write!(f, "number `{n}`"),
            Token::Str(_) => write!(f, "string"),
            Token::LineComment(_) | Token::BlockComment(_) => write!(f, "a comment"),
            other => write!(f, "`{}`", other.text().unwrap_or("?")),
        }
    }
}

impl Token {
    /// The fixed text of a keyword or punctuation token.
    pub fn text(&self) -> Option<&'static str> {
        Some(match self {
            Token::Lsystem => "lsystem",
            Token::Module => "module",
            Token::Const => "const",
            Token::Element => "element",
            Token::Palette => "palette",
            Token::Scene => "scene",
            Token::Guide => "guide",
            Token::Link => "link",
            Token::Polygon => "polygon",
            Token::System => "system",
            Token::Seed => "seed",
            Token::Heading => "heading",
            Token::Tokens => "tokens",
            Token::Edge => "edge",
            Token::With => "with",
            Token::Angle => "angle",
            Token::Derive => "derive",
            Token::Step => "step",
            Token::Axiom => "axiom",
            Token::Ignore => "ignore",
            Token::Interpret => "interpret",
            Token::Cut => "cut",
            Token::Tropism => "tropism",
            Token::Consider => "consider",
            Token::Decompose => "decompose",
            Token::True => "true",
            Token::False => "false",
            Token::Epsilon => "ε",
            Token::Arrow => "->",
            Token::Le => "<=",
            Token::Ge => ">=",
            Token::EqEq => "==",
            Token::Ne => "!=",
            Token::AndAnd => "&&",
            Token::OrOr => "||",
            Token::Lt => "<",
            Token::Gt => ">",
            Token::Assign => "=",
            Token::Colon => ":",
            Token::Semi => ";",
            Token::Comma => ",",
            Token::LParen => "(",
            Token::RParen => ")",
            Token::LBracket => "[",
            Token::RBracket => "]",
            Token::LBrace => "{",
            Token::RBrace => "}",
            Token::Plus => "+",
            Token::Minus => "-",
            Token::Star => "*",
            Token::Slash => "/",
            Token::Backslash => "\\",
            Token::Caret => "^",
            Token::Amp => "&",
            Token::Pipe => "|",
            Token::Dollar => "$",
            Token::Dot => ".",
            Token::Bang => "!",
            Token::Quote => "'",
            Token::Percent => "%",
            _ => return None,
        })
    }

    /// Words the language reserves; they cannot name parameters or items.
    pub fn is_keyword(&self) -> bool {
        matches!(self.text(), Some(t) if t.chars().all(|c| c.is_alphabetic()))
    }
}
