//! One document's analysis: the checker's diagnostics and the symbol index,
//! made again from the text on every change.
//!
//! Owns: the per-keystroke work (parse, check, index) and turning lsyc's
//! diagnostics into the protocol's (ranges in UTF-16, codes, related places,
//! warnings as warnings). It asks `frontend` exactly what `lsyc check` asks,
//! so the editor and the command line never disagree.

use super::index::Index;
use super::text::LineIndex;
use crate::ast::File;
use crate::check::Checked;
use crate::diagnostic::{Code, Diagnostic, Severity};
use crate::frontend;
use crate::span::Span;
use lsp_types as lsp;

/// The largest document analysed (the language server and the studio alike).
/// Analysis holds about 40 to 170 bytes per byte of text (a long axiom is the
/// dense end: every module a token and a node), so a document of this size
/// peaks near 350 MB; a larger one gets one E0002 diagnostic instead (see
/// docs/lsp.md).
pub const MAX_DOCUMENT_BYTES: usize = 2 << 20;

/// The diagnostic of a document over [`MAX_DOCUMENT_BYTES`], or `None`.
pub fn too_large(text: &str) -> Option<Diagnostic> {
    (text.len() > MAX_DOCUMENT_BYTES).then(|| {
        Diagnostic::error(
            Code::FileTooLarge,
            format!(
                "the document is {:.1} MiB; lsyc analyses documents up to {} MiB as you edit (`lsyc check` reads up to 64 MiB)",
                text.len() as f64 / f64::from(1 << 20),
                MAX_DOCUMENT_BYTES >> 20
            ),
        )
        .primary(Span::new(0, 0), "too large to analyse")
    })
}

pub struct Analysis {
    pub text: String,
    pub lines: LineIndex,
    pub file: File,
    pub diagnostics: Vec<Diagnostic>,
    /// The checker's findings (constants' values), when the file parsed.
    pub checked: Option<Checked>,
    pub index: Index,
}

impl Analysis {
    pub fn new(text: String) -> Analysis {
        let lines = LineIndex::new(&text);
        if let Some(d) = too_large(&text) {
            return Analysis {
                text,
                lines,
                file: File::default(),
                diagnostics: vec![d],
                checked: None,
                index: Index::default(),
            };
        }
        let fe = frontend::run(&text, Vec::new(), &[]);
        let index = Index::build(&fe.file);
        Analysis {
            text,
            lines,
            file: fe.file,
            diagnostics: fe.diagnostics,
            checked: fe.checked,
            index,
        }
    }

    /// Whether the text parsed without a syntax error (and was analysed at
    /// all): the checker runs exactly then, so `file` is the whole tree.
    pub fn parsed(&self) -> bool {
        self.checked.is_some()
    }

    pub fn range(&self, span: Span) -> lsp::Range {
        self.lines.range(&self.text, span)
    }

    pub fn offset(&self, pos: lsp::Position) -> usize {
        self.lines.offset(&self.text, pos)
    }

    /// The 1-based line of a span, for messages.
    pub fn line_of(&self, span: Span) -> usize {
        self.lines.line(span.start as usize) + 1
    }

    /// The source text of a span.
    pub fn slice(&self, span: Span) -> &str {
        self.text.get(span.range()).unwrap_or("")
    }

    /// The diagnostics as the protocol has them.
    pub fn lsp_diagnostics(&self, uri: &lsp::Uri) -> Vec<lsp::Diagnostic> {
        self.diagnostics
            .iter()
            .map(|d| self.convert(d, uri))
            .collect()
    }

    pub fn convert(&self, d: &Diagnostic, uri: &lsp::Uri) -> lsp::Diagnostic {
        let pi = d.labels.iter().position(|l| l.primary);
        let range = pi.map_or_else(lsp::Range::default, |i| self.range(d.labels[i].span));
        let mut message = d.message.clone();
        for n in &d.notes {
            message.push_str("\nnote: ");
            message.push_str(n);
        }
        if let Some(h) = &d.help {
            message.push_str("\nhelp: ");
            message.push_str(h);
        }
        let related: Vec<lsp::DiagnosticRelatedInformation> = d
            .labels
            .iter()
            .enumerate()
            .filter(|(i, _)| Some(*i) != pi)
            .map(|(_, l)| lsp::DiagnosticRelatedInformation {
                location: lsp::Location {
                    uri: uri.clone(),
                    range: self.range(l.span),
                },
                message: if l.message.is_empty() {
                    "related".to_string()
                } else {
                    l.message.clone()
                },
            })
            .collect();
        let tags = matches!(d.code, Code::Unused | Code::UnusedParameter)
            .then(|| vec![lsp::DiagnosticTag::UNNECESSARY]);
        lsp::Diagnostic {
            range,
            severity: Some(match d.severity {
                Severity::Error => lsp::DiagnosticSeverity::ERROR,
                Severity::Warning => lsp::DiagnosticSeverity::WARNING,
            }),
            code: Some(lsp::NumberOrString::String(d.code.as_str().to_string())),
            code_description: None,
            source: Some("lsyc".to_string()),
            message,
            related_information: (!related.is_empty()).then_some(related),
            tags,
            data: None,
        }
    }
}
