//! What the language's fixed words mean, in a line each: turtle symbols and
//! keywords, for hover and completion.
//!
//! Owns: the editor's short texts. They follow the turtle section and the
//! symbol table of docs/language.md; a test holds every turtle symbol the
//! lexer knows to an entry here.

/// A turtle or structure symbol, its form with a parameter, and its meaning.
pub struct TurtleWord {
    pub symbol: char,
    pub form: &'static str,
    pub meaning: &'static str,
}

const fn t(symbol: char, form: &'static str, meaning: &'static str) -> TurtleWord {
    TurtleWord {
        symbol,
        form,
        meaning,
    }
}

pub const TURTLE: &[TurtleWord] = &[
    t(
        'F',
        "F(d)",
        "draw forward d·s (the scale s); d defaults to the lsystem's `step`",
    ),
    t(
        'f',
        "f(d)",
        "move forward d·s without drawing; d defaults to the lsystem's `step`",
    ),
    t(
        '+',
        "+(a)",
        "turn left about U by a degrees (default: the lsystem's `angle`)",
    ),
    t(
        '-',
        "-(a)",
        "turn right about U by a degrees (default: the lsystem's `angle`)",
    ),
    t('&', "&(a)", "pitch down about L by a degrees (H toward −U)"),
    t('^', "^(a)", "pitch up about L by a degrees"),
    t('\\', "\\(a)", "roll left about H by a degrees"),
    t(
        '/',
        "/(a)",
        "roll right about H by a degrees; `//` starts a comment, so write `/ /`",
    ),
    t('|', "|", "turn around: 180° about U"),
    t('$', "$", "roll about H until L is horizontal"),
    t('*', "*(k)", "multiply the turtle's scale s by k"),
    t(
        '[',
        "[",
        "push the whole turtle state (position, frame, scale, width, colour)",
    ),
    t(']', "]", "pop the turtle state pushed by the matching `[`"),
    t('{', "{", "start a polygon"),
    t('}', "}", "close and fill the polygon"),
    t('.', ".", "record a polygon vertex"),
    t(
        '!',
        "!(w)",
        "set the line width to w; a bare `!` multiplies it by 0.7",
    ),
    t(
        '\'',
        "'(c)",
        "set the colour index to c; a bare `'` steps along the wood-to-leaf ramp",
    ),
    t(
        '%',
        "%",
        "cut: erase the rest of the branch (at derivation); same as `cut`",
    ),
];

pub fn turtle(c: char) -> Option<&'static TurtleWord> {
    TURTLE.iter().find(|w| w.symbol == c)
}

/// Keywords, where they may be written, and what they do.
pub struct Keyword {
    pub word: &'static str,
    pub context: Context,
    pub doc: &'static str,
}

/// Where a keyword starts a statement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Context {
    Top,
    Lsystem,
    Element,
    Scene,
    Guide,
    Link,
    /// Inside expressions or module strings.
    Anywhere,
}

const fn k(word: &'static str, context: Context, doc: &'static str) -> Keyword {
    Keyword { word, context, doc }
}

pub const KEYWORDS: &[Keyword] = &[
    k(
        "lsystem",
        Context::Top,
        "`lsystem Name(params) { … }`: an L-system: settings, an axiom and rules",
    ),
    k(
        "module",
        Context::Top,
        "`module Name(params);`: declares a multi-letter module and its parameters",
    ),
    k(
        "const",
        Context::Top,
        "`const name = value;`: a constant, overridable with `-D name=value`",
    ),
    k(
        "element",
        Context::Top,
        "`element Name { path \"…\"; }`: a terminal that prints its path at the turtle",
    ),
    k(
        "scene",
        Context::Top,
        "`scene Name { guide …; link …; }`: guides and links of an Open L-system",
    ),
    k(
        "angle",
        Context::Lsystem,
        "`angle a;`: the default turn of bare `+ - & ^ \\ /`, in degrees",
    ),
    k(
        "derive",
        Context::Lsystem,
        "`derive n;`: the default number of derivation steps",
    ),
    k(
        "step",
        Context::Lsystem,
        "`step d;`: the default length of bare `F` and `f`",
    ),
    k(
        "axiom",
        Context::Lsystem,
        "`axiom …;`: the module string derivation starts from",
    ),
    k(
        "ignore",
        Context::Lsystem,
        "`ignore + - …;`: modules context matching skips",
    ),
    k(
        "module",
        Context::Lsystem,
        "`module Name(params);`: a multi-letter module of this lsystem",
    ),
    k(
        "interpret",
        Context::Lsystem,
        "`interpret A -> …;`: a rule applied when drawing, not when deriving",
    ),
    k(
        "consider",
        Context::Lsystem,
        "`consider A B;`: context matching sees only these modules (and brackets); the complement of `ignore`, and not with it in one lsystem (E0606)",
    ),
    k(
        "tropism",
        Context::Lsystem,
        "`tropism (x, y, z) e;`: after every `F` the heading bends toward T = (x, y, z) with elasticity e (ABOP §2.2); `tropism (0, -1, 0) 0.22;` is gravity",
    ),
    k(
        "decompose",
        Context::Lsystem,
        "`decompose A -> B C;`: a decomposition rule, applied after each derivation step (not to the axiom) until none matches; chains deeper than 64 stop the run (E0910)",
    ),
    k(
        "tropism",
        Context::Anywhere,
        "`tropism(e)` in a module string: sets the tropism elasticity to e for the rest of the branch (`[` saves it, `]` restores it); a bare `tropism` goes back to the `tropism` statement's e",
    ),
    k(
        "cut",
        Context::Anywhere,
        "`cut` (or `%`): erase the rest of the branch",
    ),
    k("true", Context::Anywhere, "the boolean true"),
    k("false", Context::Anywhere, "the boolean false"),
    k(
        "path",
        Context::Element,
        "`path \"M0 0 …\";`: the element's SVG path, base at the origin, pointing +y",
    ),
    k(
        "fill",
        Context::Element,
        "`fill \"green\";`: the element's fill colour",
    ),
    k(
        "stroke",
        Context::Element,
        "`stroke \"black\";`: the element's outline colour",
    ),
    k(
        "width",
        Context::Element,
        "`width w;`: the element's outline width",
    ),
    k(
        "guide",
        Context::Scene,
        "`guide name { polygon …; system …; seed …; }`: a polygon that hosts an lsystem",
    ),
    k(
        "link",
        Context::Scene,
        "`link a.edge(i) -> b.edge(j) { tokens n; heading a; }`: messages between guides",
    ),
    k(
        "polygon",
        Context::Guide,
        "`polygon (x, y) (x, y) …;`: the guide's outline; edge i joins vertex i to i+1",
    ),
    k(
        "system",
        Context::Guide,
        "`system Name;`: the lsystem the guide hosts",
    ),
    k(
        "seed",
        Context::Guide,
        "`seed (x, y) heading a with (args);`: runs the lsystem's axiom there",
    ),
    k(
        "heading",
        Context::Guide,
        "`heading a`: the direction, in degrees",
    ),
    k(
        "with",
        Context::Guide,
        "`with (args)`: the values a seed passes to the lsystem's parameters",
    ),
    k(
        "tokens",
        Context::Link,
        "`tokens n;`: how many messages the link carries",
    ),
    k(
        "heading",
        Context::Link,
        "`heading a;`: the heading a message seeds the end guide with",
    ),
    k(
        "continue",
        Context::Link,
        "`heading continue;`: the seeded lsystem keeps the heading of the segment that crossed (streets go straight on)",
    ),
    k(
        "aim",
        Context::Link,
        "`aim middle;`: `?D_L` in the start guide measures `d` and `beta` to the middle of this link's edge, not to its closest point (often a corner); `aim closest;` is the default",
    ),
    k(
        "middle",
        Context::Link,
        "`aim middle;`: `?D_L` measures to the middle of the link's edge",
    ),
    k(
        "closest",
        Context::Link,
        "`aim closest;` (the default): `?D_L` measures to the closest point of the link's edge",
    ),
    k(
        "take",
        Context::Link,
        "`take v;`: only a `?X` whose second parameter (the first after Δ) equals v takes this link's tokens: the leader's `?X(D, 1)`, the side shoots' `?X(D, 0)`",
    ),
    k(
        "edge",
        Context::Scene,
        "`guide.edge(i)`: edge i of a guide's polygon",
    ),
];

/// The keyword's text for hover (the first entry for a word).
pub fn keyword(word: &str) -> Option<&'static Keyword> {
    KEYWORDS.iter().find(|k| k.word == word)
}

/// Whether a name is one of the named settings a link takes (`aim`, `take`).
pub fn is_link_setting(name: &str) -> bool {
    matches!(name, "aim" | "take")
}

/// The text of a word written where a name could be (`Target::Word`): the
/// module `tropism(e)` in a string, a link setting or its value.
pub fn word(word: &str) -> Option<&'static Keyword> {
    KEYWORDS
        .iter()
        .find(|k| k.word == word && matches!(k.context, Context::Anywhere | Context::Link))
        .or_else(|| keyword(word))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lexer::{Token, lex};

    #[test]
    fn every_symbol_the_lexer_knows_has_a_meaning() {
        for c in "+-&^\\/|$*[]{}.!'%".chars() {
            let text = c.to_string();
            let lexed = lex(&text);
            assert!(lexed.diagnostics.is_empty(), "{c}");
            assert!(turtle(c).is_some(), "no meaning for {c}");
        }
        for w in KEYWORDS {
            let lexed = lex(w.word);
            let is_kw = matches!(&lexed.tokens[..], [(_, t, _)] if t.is_keyword());
            let is_prop = matches!(&lexed.tokens[..], [(_, Token::Ident(_), _)]);
            assert!(is_kw || is_prop, "{} is not a word of the language", w.word);
        }
    }
}
