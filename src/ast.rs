//! The syntax tree of a `.lsy` file, with spans and the comments a person wrote.
//!
//! Owns: the shape of programs as the parser produces them and as `fmt` prints
//! them; inference and editing build the same types. Must not hold derived facts
//! (types, resolved ids): those belong to the checker and the compiler.

use crate::lexer::Comment;
use crate::span::Span;

/// A name as written, with its place.
#[derive(Clone, Debug, PartialEq)]
pub struct Ident {
    pub name: String,
    pub span: Span,
}

impl Ident {
    pub fn new(name: impl Into<String>) -> Ident {
        Ident {
            name: name.into(),
            span: Span::default(),
        }
    }
}

/// Comments and spacing around a statement-like node.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trivia {
    /// Comments on the lines before the node (and any written inside it).
    pub leading: Vec<Comment>,
    /// A comment after the node on its last line.
    pub trailing: Option<Comment>,
    /// Whether a blank line separates the node from the one before it.
    pub blank_before: bool,
    /// Whether a blank line separates the leading comments from the node (a file
    /// header stays apart from the first item).
    pub blank_after_leading: bool,
}

/// A statement-like node: an item, a statement in a block, a property.
#[derive(Clone, Debug, PartialEq)]
pub struct Node<T> {
    pub trivia: Trivia,
    pub node: T,
    pub span: Span,
}

impl<T> Node<T> {
    pub fn new(node: T, span: Span) -> Node<T> {
        Node {
            trivia: Trivia::default(),
            node,
            span,
        }
    }
}

/// A `{ … }` body: its statements and the comments left before `}`.
#[derive(Clone, Debug, PartialEq)]
pub struct Block<T> {
    pub stmts: Vec<Node<T>>,
    pub end_comments: Vec<Comment>,
}

impl<T> Default for Block<T> {
    fn default() -> Self {
        Block {
            stmts: Vec::new(),
            end_comments: Vec::new(),
        }
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct File {
    pub items: Block<Item>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    Lsystem(Lsystem),
    Module(ModuleDecl),
    Const(ConstDecl),
    Element(Element),
    Palette(Palette),
    Scene(Scene),
    /// A region the parser skipped after a syntax error.
    Error,
}

/// `palette { 0 "#263238"; 4 "#4f7f2f" leaf; }`: the colours of `'(c)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Palette {
    /// The keyword's span (the item has no name).
    pub keyword: Span,
    pub body: Block<PaletteEntry>,
}

/// `INDEX "COLOUR" NAME?;` in a palette.
#[derive(Clone, Debug, PartialEq)]
pub struct PaletteEntry {
    pub index: Expr,
    pub color: String,
    pub color_span: Span,
    /// The material name OBJ and glTF give the colour.
    pub name: Option<Ident>,
}

/// `lsystem Name(params) { … }`
#[derive(Clone, Debug, PartialEq)]
pub struct Lsystem {
    pub name: Ident,
    /// Values a seed or a message passes in; the axiom may use them.
    pub params: Vec<Ident>,
    pub body: Block<Stmt>,
}

// Rules are most statements; boxing them would only add indirection.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Stmt {
    Angle(Expr),
    Derive(Expr),
    Step(Expr),
    Axiom(Vec<Module>),
    Ignore(Vec<Module>),
    /// `consider A B;`: context matching sees only these modules (and brackets).
    Consider(Vec<Module>),
    /// `tropism (x, y, z) e;`: after every `F` the heading bends toward T.
    Tropism(Tropism),
    Module(ModuleDecl),
    Rule(Rule),
    Error,
}

/// `tropism (x, y, z) e;`: the tropism vector T and the elasticity e (ABOP §2.2).
#[derive(Clone, Debug, PartialEq)]
pub struct Tropism {
    pub dir: [Expr; 3],
    pub elasticity: Expr,
}

/// `module Apex(len, depth);`
#[derive(Clone, Debug, PartialEq)]
pub struct ModuleDecl {
    pub name: Ident,
    pub params: Vec<Ident>,
}

/// `const N = 5;`
#[derive(Clone, Debug, PartialEq)]
pub struct ConstDecl {
    pub name: Ident,
    pub value: Expr,
}

/// `label: interpret L < P(x) > R : cond ->(weight) successor;`
#[derive(Clone, Debug, PartialEq)]
pub struct Rule {
    pub label: Option<Ident>,
    /// A homomorphism (interpretation) rule: applied when drawing, not when deriving.
    pub interpret: bool,
    /// A decomposition rule: applied after each derivation step until none matches.
    pub decompose: bool,
    pub left: Option<Vec<Module>>,
    pub pred: Module,
    pub right: Option<Vec<Module>>,
    pub cond: Option<Expr>,
    pub weight: Option<Expr>,
    pub succ: Vec<Module>,
}

/// One module of a module string: a letter, a declared name, a turtle symbol,
/// a query module or `cut`, with optional parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Module {
    pub name: ModName,
    pub name_span: Span,
    /// `None` when written bare (`F`), `Some(vec![])` for `F()`.
    pub args: Option<Vec<Expr>>,
    pub span: Span,
}

impl Module {
    pub fn new(name: ModName, args: Option<Vec<Expr>>) -> Module {
        Module {
            name,
            name_span: Span::default(),
            args,
            span: Span::default(),
        }
    }

    pub fn arity(&self) -> usize {
        self.args.as_ref().map_or(0, Vec::len)
    }
}

#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ModName {
    /// A single letter or a declared multi-letter name. Before resolution an
    /// undeclared run of letters is one `Name`; the resolver splits it.
    Name(String),
    /// A turtle or structure symbol: `+ - & ^ \ / | $ * [ ] { } . ! ' %`.
    Symbol(char),
    /// `?X`, `?D_L`, … including the `?`.
    Query(String),
    /// The keyword `cut` (same meaning as `%`).
    Cut,
}

impl ModName {
    /// The module as written in source.
    pub fn text(&self) -> std::borrow::Cow<'_, str> {
        match self {
            ModName::Name(s) | ModName::Query(s) => s.as_str().into(),
            ModName::Symbol(c) => c.to_string().into(),
            ModName::Cut => "cut".into(),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

impl Expr {
    pub fn new(kind: ExprKind) -> Expr {
        Expr {
            kind,
            span: Span::default(),
        }
    }

    pub fn num(v: f64) -> Expr {
        Expr::new(ExprKind::Num(v))
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    Num(f64),
    Bool(bool),
    Var(String),
    Unary(UnOp, Box<Expr>),
    Binary(BinOp, Box<Expr>, Box<Expr>),
    Call(Ident, Vec<Expr>),
    /// Stands in for an expression the parser could not build.
    Error,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnOp {
    Neg,
    Not,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    Or,
    And,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    Pow,
}

impl BinOp {
    pub fn text(self) -> &'static str {
        match self {
            BinOp::Or => "||",
            BinOp::And => "&&",
            BinOp::Eq => "==",
            BinOp::Ne => "!=",
            BinOp::Lt => "<",
            BinOp::Le => "<=",
            BinOp::Gt => ">",
            BinOp::Ge => ">=",
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Rem => "%",
            BinOp::Pow => "^",
        }
    }

    /// Binding strength: higher binds tighter.
    pub fn precedence(self) -> u8 {
        match self {
            BinOp::Or => 1,
            BinOp::And => 2,
            BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => 3,
            BinOp::Add | BinOp::Sub => 4,
            BinOp::Mul | BinOp::Div | BinOp::Rem => 5,
            BinOp::Pow => 7,
        }
    }

    pub fn is_comparison(self) -> bool {
        self.precedence() == 3
    }

    pub fn is_logical(self) -> bool {
        matches!(self, BinOp::Or | BinOp::And)
    }
}

/// Precedence of unary operators (between `*` and `^`).
pub const UNARY_PRECEDENCE: u8 = 6;

/// `element Leaf { path "M0 0 …"; fill "green"; }`
#[derive(Clone, Debug, PartialEq)]
pub struct Element {
    pub name: Ident,
    pub props: Block<Prop>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Prop {
    pub key: Ident,
    pub value: PropValue,
}

#[derive(Clone, Debug, PartialEq)]
pub enum PropValue {
    Str(String, Span),
    Expr(Expr),
}

/// `scene Name { guide …; link …; }`
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub name: Ident,
    pub body: Block<SceneStmt>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum SceneStmt {
    Guide(Guide),
    Link(Link),
    Error,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Guide {
    pub name: Ident,
    pub body: Block<GuideStmt>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum GuideStmt {
    /// `polygon (x, y) (x, y) …;` edge i joins vertex i to vertex i+1.
    Polygon(Vec<Point>),
    /// `system Name;`
    System(Ident),
    /// `seed (x, y) heading a with (args);`
    Seed(Seed),
    Error,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub x: Expr,
    pub y: Expr,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Seed {
    pub at: Point,
    pub heading: Option<Expr>,
    pub args: Option<Vec<Expr>>,
}

/// `link a.edge(2) -> b.edge(0) { tokens 1; heading 30; }`
#[derive(Clone, Debug, PartialEq)]
pub struct Link {
    pub from: EdgeRef,
    pub to: EdgeRef,
    pub body: Block<LinkStmt>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct EdgeRef {
    pub guide: Ident,
    pub index: Expr,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum LinkStmt {
    Tokens(Expr),
    /// `heading a;`, or `heading continue;` (the name `continue`).
    Heading(Expr),
    /// `aim middle;`, `take 1;`: a named setting (the checker knows the names).
    Setting(Ident, Expr),
    Error,
}
