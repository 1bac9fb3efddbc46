//! Diagnostics as data, and the one place they are rendered.
//!
//! Owns: `Diagnostic` (severity, stable code, message, labels, notes, help) and its
//! three renderings: coloured or plain terminal text through codespan-reporting, and
//! JSON for tools. Phases build diagnostics where they find a problem; they never
//! format terminal strings themselves.
//!
//! One rendering path: the command line draws diagnostics with
//! codespan-reporting (`render`). For other Rust programs a `Diagnostic` is
//! also a `std::error::Error` and a `miette::Diagnostic` (code, severity, help,
//! labels); `Diagnostic::in_source` attaches the source text so that a miette
//! report handler can draw it the same way. Each layer's typed error
//! (`CompileError`, `SceneError`, `DeriveError`, `ExprError`) turns into a
//! `Diagnostic` with `.diagnostic()`.

use crate::span::{LineIndex, Span};
use codespan_reporting::diagnostic as cs;
use codespan_reporting::files::SimpleFile;
use codespan_reporting::term;
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Error,
    Warning,
}

macro_rules! codes {
    ($($variant:ident = $code:literal, $title:literal;)*) => {
        /// Stable diagnostic codes. A code never changes meaning once released;
        /// `docs/language.md` lists them all.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Code { $($variant,)* }

        impl Code {
            pub const ALL: &'static [Code] = &[$(Code::$variant,)*];

            /// The code as printed: `E0201`, `W0101`.
            pub fn as_str(self) -> &'static str {
                match self { $(Code::$variant => $code,)* }
            }

            /// A short title for the code, used in the reference.
            pub fn title(self) -> &'static str {
                match self { $(Code::$variant => $title,)* }
            }
        }
    };
}

codes! {
    ReadFile = "E0001", "the input file cannot be read";
    FileTooLarge = "E0002", "the input file is too large";
    WriteOutput = "E0003", "an output file that cannot be written";
    InvalidUtf8 = "E0101", "the source is not valid UTF-8";
    NulByte = "E0102", "the source contains a NUL byte";
    UnexpectedChar = "E0103", "a character that cannot start any token";
    UnterminatedComment = "E0104", "a block comment without `*/`";
    UnterminatedString = "E0105", "a string without its closing quote";
    NumberOutOfRange = "E0106", "a number literal too large to represent";
    InvalidEscape = "E0107", "an unknown escape sequence in a string";
    UnexpectedToken = "E0201", "a token the grammar does not allow here";
    UnexpectedEof = "E0202", "the file ends in the middle of an item";
    TooDeep = "E0203", "an expression nested too deeply";
    UndeclaredModule = "E0301", "a multi-letter module name that is not declared";
    UnknownName = "E0302", "a name that is not a parameter or constant";
    UnknownFunction = "E0303", "a call of a function that does not exist";
    Duplicate = "E0304", "a name defined twice in one scope";
    UnknownQuery = "E0305", "a query module that the environment does not answer";
    UnknownSystem = "E0306", "a scene refers to an lsystem that does not exist";
    UnknownGuide = "E0307", "a link refers to a guide that does not exist";
    PatternNotName = "E0308", "a predecessor parameter that is not a plain name";
    NotRewritable = "E0309", "a predecessor symbol that cannot be rewritten";
    ArityDeclared = "E0401", "a module used with a different number of parameters than declared";
    ArityRules = "E0402", "a module used with a different number of parameters than its rules take";
    ArityFunction = "E0403", "a function called with the wrong number of arguments";
    QuerySignature = "E0404", "a query module written against its fixed signature";
    ArgsNotAllowed = "E0405", "parameters on a symbol that takes none";
    TooManyParameters = "E0406", "a module with more than 255 parameters";
    TypeMismatch = "E0501", "a boolean where a number is needed, or the reverse";
    ConditionNotBool = "E0502", "a rule condition that is not a boolean";
    ConstCycle = "E0503", "constants defined in terms of each other";
    NotConstant = "E0504", "a value that must be known before derivation uses a parameter";
    OutOfRange = "E0505", "a value outside the range its setting allows";
    BadOverride = "E0506", "a `-D NAME=VALUE` override that does not fit the program";
    UnbalancedBrackets = "E0601", "`[` and `]` that do not pair up";
    UnbalancedPolygon = "E0602", "`{` and `}` that do not pair up";
    MissingAxiom = "E0603", "an lsystem without an axiom";
    DuplicateSetting = "E0604", "a setting given twice";
    NoLsystem = "E0605", "a file with no lsystem to run";
    IgnoreAndConsider = "E0606", "`ignore` and `consider` in one lsystem";
    ContextNotAllowed = "E0607", "context on an `interpret` or `decompose` rule";
    InvalidPath = "E0701", "element path data that is not valid SVG";
    MissingPath = "E0702", "an element without a shape (`path`, `sphere`, `disk`, `patch`, `mesh` or `contour`)";
    UnknownProperty = "E0703", "an element property lsyc does not know";
    PropertyKind = "E0704", "an element property with the wrong kind of value";
    PolygonTooSmall = "E0801", "a guide polygon with fewer than three vertices";
    EdgeOutOfRange = "E0802", "an edge index beyond the polygon's edges";
    GuideIncomplete = "E0803", "a guide without a polygon or without a system";
    SeedArguments = "E0804", "a seed passing a different number of arguments than its lsystem takes";
    LinkSetting = "E0805", "a link setting lsyc does not know, or a value it does not take";
    SceneNeverSettles = "E0806", "a scene still growing when it has run the most steps a scene runs";
    DivisionByZero = "E0901", "a division by zero while running";
    NotFinite = "E0902", "an expression whose value is not a finite number while running";
    TooManyModules = "E0903", "a derivation step that would exceed the module limit";
    TooMuchMemory = "E0904", "a derivation step that would exceed the memory limit";
    InterpretTooDeep = "E0905", "interpretation rules that expand into each other too deeply";
    TooManySymbols = "E0906", "a program with more distinct modules than the string can number";
    TooManySteps = "E0907", "more derivation steps than the limit";
    TooMuchDrawing = "E0908", "interpretation that would draw more than the module limit";
    DrawingTooLarge = "E0909", "a drawing with coordinates too large to write";
    DecomposeTooDeep = "E0910", "decomposition rules that expand into each other too deeply";
    MeshFile = "E0911", "a `mesh` file that cannot be read as OBJ";
    Cancelled = "E0912", "a run stopped because a newer request replaced it (`lsyc studio`)";
    TwoShapes = "E0705", "an element with more than one shape";
    BadOrgan = "E0706", "organ or contour data that makes no shape";
    Unused = "W0101", "a declaration that nothing uses";
    UnusedParameter = "W0102", "a rule parameter that nothing uses";
    NeverProduced = "W0201", "a rule whose predecessor never appears";
    Shadowed = "W0202", "a rule hidden by an earlier rule that always applies";
    AlwaysFalse = "W0203", "a rule whose condition is always false";
    SplitWord = "W0301", "a word read as a run of single-letter modules";
    ArityNeverRewritten = "W0302", "a turtle symbol whose parameter count no rule matches";
    NeverSeeded = "W0801", "a guide never seeded while a link to it kept its tokens";
    DeriveRanOut = "W0802", "a system stopped by `derive` with query modules still to answer";
    LeavesAndComesBack = "W0803", "growth that leaves its guide and comes back in";
    DoesNothing = "W0303", "a letter with parameters that no rule rewrites and nothing draws";
    StarContext = "W0304", "`*` in a context, read as the scale module and not as a wildcard";
    SectionLabel = "W0305", "a rule label that is a section name of cpfg or L-Py";
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Label {
    pub span: Span,
    pub message: String,
    pub primary: bool,
}

/// One finding about the input: built where the problem is found, rendered elsewhere.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    pub severity: Severity,
    pub code: Code,
    pub message: String,
    pub labels: Vec<Label>,
    pub notes: Vec<String>,
    pub help: Option<String>,
    /// Machine-applicable fixes for what `help` says (editors offer them as
    /// quick fixes); most diagnostics have none. (A boxed slice: diagnostics
    /// travel in `Result`s, and this keeps them small.)
    pub fixes: Box<[Fix]>,
}

/// A concrete fix: replace each span with its text. Applying it gives a
/// program that no longer has this problem.
#[derive(Clone, Debug, PartialEq)]
pub struct Fix {
    /// What it does, in a few words ("replace with `crown`").
    pub title: String,
    pub edits: Vec<(Span, String)>,
}

impl Diagnostic {
    pub fn error(code: Code, message: impl Into<String>) -> Diagnostic {
        Diagnostic {
            severity: Severity::Error,
            code,
            message: message.into(),
            labels: Vec::new(),
            notes: Vec::new(),
            help: None,
            fixes: Box::new([]),
        }
    }

    pub fn warning(code: Code, message: impl Into<String>) -> Diagnostic {
        Diagnostic {
            severity: Severity::Warning,
            ..Diagnostic::error(code, message)
        }
    }

    /// The main place of the problem.
    pub fn primary(mut self, span: Span, message: impl Into<String>) -> Diagnostic {
        self.labels.push(Label {
            span,
            message: message.into(),
            primary: true,
        });
        self
    }

    /// A related place that explains the problem.
    pub fn secondary(mut self, span: Span, message: impl Into<String>) -> Diagnostic {
        self.labels.push(Label {
            span,
            message: message.into(),
            primary: false,
        });
        self
    }

    pub fn note(mut self, note: impl Into<String>) -> Diagnostic {
        self.notes.push(note.into());
        self
    }

    pub fn help(mut self, help: impl Into<String>) -> Diagnostic {
        self.help = Some(help.into());
        self
    }

    /// A machine-applicable fix: write `text` in place of `span`.
    pub fn fix(
        mut self,
        title: impl Into<String>,
        span: Span,
        text: impl Into<String>,
    ) -> Diagnostic {
        let mut fixes = std::mem::take(&mut self.fixes).into_vec();
        fixes.push(Fix {
            title: title.into(),
            edits: vec![(span, text.into())],
        });
        self.fixes = fixes.into_boxed_slice();
        self
    }

    /// "did you mean `name`?", and the fix that writes `name` at `span`.
    pub fn did_you_mean(self, span: Span, name: &str) -> Diagnostic {
        self.help(format!("did you mean `{name}`?")).fix(
            format!("replace with `{name}`"),
            span,
            name,
        )
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// The start of the first primary label, for sorting.
    pub fn position(&self) -> u32 {
        self.labels
            .iter()
            .find(|l| l.primary)
            .map(|l| l.span.start)
            .unwrap_or(0)
    }
}

impl std::fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Diagnostic {}

impl miette::Diagnostic for Diagnostic {
    fn code<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        Some(Box::new(self.code.as_str()))
    }

    fn severity(&self) -> Option<miette::Severity> {
        Some(match self.severity {
            Severity::Error => miette::Severity::Error,
            Severity::Warning => miette::Severity::Warning,
        })
    }

    fn help<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        let mut parts: Vec<&str> = self.notes.iter().map(String::as_str).collect();
        parts.extend(self.help.as_deref());
        (!parts.is_empty()).then(|| Box::new(parts.join("\n")) as Box<dyn std::fmt::Display>)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        if self.labels.is_empty() {
            return None;
        }
        Some(Box::new(self.labels.iter().map(|l| {
            let span = l.span.range();
            let text = (!l.message.is_empty()).then(|| l.message.clone());
            if l.primary {
                miette::LabeledSpan::new_primary_with_span(text, span)
            } else {
                miette::LabeledSpan::new_with_span(text, span)
            }
        })))
    }
}

/// A diagnostic with the text it points into, for miette's report handlers.
#[derive(Debug)]
pub struct InSource {
    pub diagnostic: Diagnostic,
    source: miette::NamedSource<String>,
}

impl Diagnostic {
    /// This diagnostic together with its file's name and text.
    pub fn in_source(self, name: &str, text: &str) -> InSource {
        InSource {
            diagnostic: self,
            source: miette::NamedSource::new(name, text.to_string()),
        }
    }
}

impl std::fmt::Display for InSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.diagnostic.fmt(f)
    }
}

impl std::error::Error for InSource {}

impl miette::Diagnostic for InSource {
    fn code<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        miette::Diagnostic::code(&self.diagnostic)
    }

    fn severity(&self) -> Option<miette::Severity> {
        miette::Diagnostic::severity(&self.diagnostic)
    }

    fn help<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        miette::Diagnostic::help(&self.diagnostic)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        miette::Diagnostic::labels(&self.diagnostic)
    }

    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        Some(&self.source)
    }
}

/// Sorts diagnostics by position (stable), so output follows the file.
pub fn sort(diags: &mut [Diagnostic]) {
    diags.sort_by_key(|d| d.position());
}

/// How diagnostics are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// codespan-reporting's rich terminal form.
    Human { color: bool },
    /// One JSON object per line.
    Json,
}

/// Renders diagnostics about `source` (named `file` in the output) to a string.
pub fn render(diags: &[Diagnostic], file: &str, source: &str, format: Format) -> String {
    match format {
        Format::Human { color } => render_human(diags, file, source, color),
        Format::Json => render_json(diags, file, source),
    }
}

fn to_codespan(d: &Diagnostic, source_len: usize) -> cs::Diagnostic<()> {
    let severity = match d.severity {
        Severity::Error => cs::Severity::Error,
        Severity::Warning => cs::Severity::Warning,
    };
    let labels = d
        .labels
        .iter()
        .map(|l| {
            let start = (l.span.start as usize).min(source_len);
            let end = (l.span.end as usize).clamp(start, source_len);
            let style = if l.primary {
                cs::LabelStyle::Primary
            } else {
                cs::LabelStyle::Secondary
            };
            cs::Label::new(style, (), start..end).with_message(l.message.clone())
        })
        .collect::<Vec<_>>();
    // A diagnostic about the whole file (no place in it) still names the file:
    // codespan prints the location of a label, so it gets an empty one at 1:1.
    let labels = if labels.is_empty() && source_len > 0 {
        vec![cs::Label::primary((), 0..0)]
    } else {
        labels
    };
    let mut notes = d.notes.clone();
    if let Some(h) = &d.help {
        notes.push(format!("help: {h}"));
    }
    cs::Diagnostic::new(severity)
        .with_code(d.code.as_str())
        .with_message(d.message.clone())
        .with_labels(labels)
        .with_notes(notes)
}

fn render_human(diags: &[Diagnostic], file: &str, source: &str, color: bool) -> String {
    let files = SimpleFile::new(file, source);
    let config = term::Config::default();
    if color {
        let mut buf = term::termcolor::Buffer::ansi();
        for d in diags {
            // Rendering into memory cannot fail for spans clamped to the source.
            let _ =
                term::emit_to_write_style(&mut buf, &config, &files, &to_codespan(d, source.len()));
        }
        String::from_utf8_lossy(buf.as_slice()).into_owned()
    } else {
        let mut out = String::new();
        for d in diags {
            let _ = term::emit_to_string(&mut out, &config, &files, &to_codespan(d, source.len()));
        }
        out
    }
}

#[derive(Serialize)]
struct JsonLabel<'a> {
    line: usize,
    column: usize,
    end_line: usize,
    end_column: usize,
    start: u32,
    end: u32,
    message: &'a str,
    primary: bool,
}

#[derive(Serialize)]
struct JsonDiagnostic<'a> {
    file: &'a str,
    severity: Severity,
    code: &'static str,
    message: &'a str,
    line: Option<usize>,
    column: Option<usize>,
    labels: Vec<JsonLabel<'a>>,
    notes: &'a [String],
    help: Option<&'a str>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    fixes: Vec<JsonFix<'a>>,
}

/// A machine-applicable fix: apply all its edits (spans of the original text)
/// at once, as the language server's quick fixes do.
#[derive(Serialize)]
struct JsonFix<'a> {
    title: &'a str,
    edits: Vec<JsonEdit<'a>>,
}

#[derive(Serialize)]
struct JsonEdit<'a> {
    line: usize,
    column: usize,
    end_line: usize,
    end_column: usize,
    start: u32,
    end: u32,
    replacement: &'a str,
}

fn render_json(diags: &[Diagnostic], file: &str, source: &str) -> String {
    let index = LineIndex::new(source);
    let mut out = String::new();
    for d in diags {
        let labels: Vec<JsonLabel> = d
            .labels
            .iter()
            .map(|l| {
                let (line, column) = index.line_col(source, l.span.start as usize);
                let (end_line, end_column) = index.line_col(source, l.span.end as usize);
                JsonLabel {
                    line,
                    column,
                    end_line,
                    end_column,
                    start: l.span.start,
                    end: l.span.end,
                    message: &l.message,
                    primary: l.primary,
                }
            })
            .collect();
        let first = labels.iter().find(|l| l.primary);
        let fixes = d
            .fixes
            .iter()
            .map(|f| JsonFix {
                title: &f.title,
                edits: f
                    .edits
                    .iter()
                    .map(|(span, replacement)| {
                        let (line, column) = index.line_col(source, span.start as usize);
                        let (end_line, end_column) = index.line_col(source, span.end as usize);
                        JsonEdit {
                            line,
                            column,
                            end_line,
                            end_column,
                            start: span.start,
                            end: span.end,
                            replacement,
                        }
                    })
                    .collect(),
            })
            .collect();
        let json = JsonDiagnostic {
            file,
            severity: d.severity,
            code: d.code.as_str(),
            message: &d.message,
            line: first.map(|l| l.line),
            column: first.map(|l| l.column),
            notes: &d.notes,
            help: d.help.as_deref(),
            labels,
            fixes,
        };
        if let Ok(s) = serde_json::to_string(&json) {
            out.push_str(&s);
            out.push('\n');
        }
    }
    out
}
