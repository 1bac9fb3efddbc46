//! Semantic tokens: every name coloured by what it means, not by how it
//! looks. A letter `A` that a rule rewrites is a module, `x` in a rule a
//! parameter, `N` a constant, `?X` a query module, `F` a turtle module.
//!
//! Owns: the legend and the encoding. Meanings come from the index; keywords,
//! numbers, strings and comments from the lexer (the same tokens the parser
//! reads). Where both speak (the module `tropism`), the index wins.

use super::analysis::Analysis;
use super::index::{Kind, Target};
use crate::lexer::{Token, lex};
use crate::resolve::is_letter;
use crate::span::Span;
use lsp_types::{
    SemanticToken, SemanticTokenModifier, SemanticTokenType, SemanticTokens, SemanticTokensLegend,
};

/// Token types, in legend order (a token's type is its index here).
const TYPES: &[SemanticTokenType] = &[
    SemanticTokenType::KEYWORD,   // 0
    SemanticTokenType::VARIABLE,  // 1 constants (readonly)
    SemanticTokenType::PARAMETER, // 2
    SemanticTokenType::TYPE,      // 3 modules: declared, letters, query modules
    SemanticTokenType::STRUCT,    // 4 elements
    SemanticTokenType::CLASS,     // 5 lsystems
    SemanticTokenType::NAMESPACE, // 6 scenes
    SemanticTokenType::PROPERTY,  // 7 guides
    SemanticTokenType::OPERATOR,  // 8 turtle symbols
    SemanticTokenType::FUNCTION,  // 9 built-in functions
    SemanticTokenType::NUMBER,    // 10
    SemanticTokenType::STRING,    // 11
    SemanticTokenType::COMMENT,   // 12
];

/// Modifiers, in legend order (bit i is modifier i).
const MODIFIERS: &[SemanticTokenModifier] = &[
    SemanticTokenModifier::DECLARATION,     // 1
    SemanticTokenModifier::READONLY,        // 2
    SemanticTokenModifier::DEFAULT_LIBRARY, // 4: the language's own (queries, turtle, functions)
];

const DECLARATION: u32 = 1;
const READONLY: u32 = 2;
const LIBRARY: u32 = 4;

pub fn legend() -> SemanticTokensLegend {
    SemanticTokensLegend {
        token_types: TYPES.to_vec(),
        token_modifiers: MODIFIERS.to_vec(),
    }
}

/// One token before encoding: a byte span, a type index and modifier bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Raw {
    pub span: Span,
    pub ty: u32,
    pub mods: u32,
}

/// The type name of a token type index (for tests and tools).
pub fn type_name(ty: u32) -> &'static str {
    TYPES.get(ty as usize).map_or("?", |t| t.as_str())
}

/// The file's tokens in order, without overlaps.
pub fn raw(a: &Analysis) -> Vec<Raw> {
    let mut out: Vec<Raw> = Vec::new();
    for o in &a.index.occurrences {
        let decl = if o.decl { DECLARATION } else { 0 };
        let (ty, mods) = match &o.target {
            Target::Symbol(id) => {
                let s = &a.index.symbols[*id];
                match s.kind {
                    Kind::Const => (1, READONLY),
                    Kind::Param => (2, 0),
                    Kind::Module => (3, 0),
                    Kind::Letter if is_letter(&s.name) && matches!(s.name.as_str(), "F" | "f") => {
                        (3, LIBRARY)
                    }
                    Kind::Letter => (3, 0),
                    Kind::Element => (4, 0),
                    Kind::Lsystem => (5, 0),
                    Kind::Scene => (6, 0),
                    Kind::Guide => (7, 0),
                }
            }
            Target::Query(_) => (3, LIBRARY),
            Target::Turtle(_) => (8, LIBRARY),
            Target::Cut | Target::Word(_) => (0, 0),
            Target::Function(_) => (9, LIBRARY),
        };
        out.push(Raw {
            span: o.span,
            ty,
            mods: mods | decl,
        });
    }
    let lexed = lex(&a.text);
    for (s, t, e) in &lexed.tokens {
        let ty = match t {
            Token::Number(_) => 10,
            Token::Str(_) => 11,
            t if t.is_keyword() => 0,
            _ => continue,
        };
        out.push(Raw {
            span: Span::new(*s, *e),
            ty,
            mods: 0,
        });
    }
    for c in &lexed.comments {
        out.push(Raw {
            span: c.span,
            ty: 12,
            mods: 0,
        });
    }
    // Index first at equal starts (the sort is stable), then drop overlaps.
    out.sort_by_key(|r| r.span.start);
    let mut kept: Vec<Raw> = Vec::with_capacity(out.len());
    for r in out {
        if r.span.is_empty() || kept.last().is_some_and(|k| r.span.start < k.span.end) {
            continue;
        }
        kept.push(r);
    }
    kept
}

/// The tokens as the protocol encodes them: relative lines and UTF-16
/// columns, one token per line (a block comment over lines becomes several).
pub fn tokens(a: &Analysis) -> SemanticTokens {
    let mut data = Vec::new();
    let (mut line, mut col) = (0u32, 0u32);
    for r in raw(a) {
        let mut start = r.span.start as usize;
        let end = r.span.end as usize;
        while start < end {
            let piece_end = a.text[start..end]
                .find(['\n', '\r'])
                .map_or(end, |i| start + i);
            if piece_end > start {
                let range = a.range(Span::new(start, piece_end));
                let p = range.start;
                let length = range.end.character - p.character;
                let delta_line = p.line - line;
                let delta_start = if delta_line == 0 {
                    p.character - col
                } else {
                    p.character
                };
                data.push(SemanticToken {
                    delta_line,
                    delta_start,
                    length,
                    token_type: r.ty,
                    token_modifiers_bitset: r.mods,
                });
                line = p.line;
                col = p.character;
            }
            // Past the line break (`\r\n` is one).
            start = piece_end;
            while start < end && matches!(a.text.as_bytes()[start], b'\n' | b'\r') {
                start += 1;
            }
        }
    }
    SemanticTokens {
        result_id: None,
        data,
    }
}
