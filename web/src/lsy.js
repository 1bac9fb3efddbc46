// Syntax highlighting of .lsy programs: a CodeMirror stream language whose
// words and tokens follow lsyc's lexer (src/lexer.rs).
import { StreamLanguage } from "@codemirror/language";

const KEYWORDS = new Set([
  "lsystem", "module", "const", "element", "scene", "guide", "link", "polygon",
  "system", "seed", "heading", "tokens", "edge", "with", "angle", "derive", "step",
  "axiom", "ignore", "consider", "decompose", "interpret", "cut", "tropism",
  "path", "fill", "stroke", "width",
]);
const ATOMS = new Set(["true", "false", "ε"]);

export const lsy = StreamLanguage.define({
  name: "lsy",
  startState: () => ({ comment: false }),
  token(stream, state) {
    if (state.comment) {
      if (stream.skipTo("*/")) {
        stream.next();
        stream.next();
        state.comment = false;
      } else {
        stream.skipToEnd();
      }
      return "comment";
    }
    if (stream.eatSpace()) return null;
    if (stream.match("//")) {
      stream.skipToEnd();
      return "comment";
    }
    if (stream.match("/*")) {
      state.comment = true;
      return "comment";
    }
    if (stream.match(/^"(?:[^"\\]|\\.)*"?/)) return "string";
    if (stream.match(/^(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?/)) return "number";
    if (stream.match(/^\?[\p{L}_][\p{L}\p{N}_]*/u)) return "meta";
    const word = stream.match(/^[\p{L}_][\p{L}\p{N}_]*/u);
    if (word) {
      const w = word[0];
      if (stream.peek() === ":" && !stream.string.startsWith(":", stream.pos + 1)) return "labelName";
      if (KEYWORDS.has(w)) return "keyword";
      if (ATOMS.has(w)) return "atom";
      if (/^[A-Z]/.test(w)) return "typeName";
      return "variableName";
    }
    if (stream.match(/^(?:->|<=|>=|==|!=|&&|\|\|)/)) return "operator";
    const ch = stream.next();
    if ("()[]{}".includes(ch)) return "bracket";
    if ("+-*/\\^&|$!'%<>=.".includes(ch)) return "operator";
    return null;
  },
  languageData: { commentTokens: { line: "//", block: { open: "/*", close: "*/" } } },
});
