#!/usr/bin/env python3
"""Renders a real `lsyc lsp` session as a page, for the README's picture.

There is no VS Code on a build machine, so this script plays the editor: it
starts `lsyc lsp`, opens a gallery program with two mistakes typed into it,
asks for a hover, and draws the text with the diagnostics and the hover exactly
as the server sent them (squiggles at the ranges, the problems list with codes,
the hover's markdown). Chromium's headless mode turns the page into a PNG:

    python3 editors/demo/session.py target/debug/lsyc /tmp/lsp-session.html
    chromium --headless --hide-scrollbars --window-size=1180,660 \
        --screenshot=docs/lsp-session.png /tmp/lsp-session.html
"""

import html
import json
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


class Client:
    def __init__(self, lsyc):
        self.p = subprocess.Popen([lsyc, "lsp"], stdin=subprocess.PIPE, stdout=subprocess.PIPE)
        self.id = 0

    def send(self, obj):
        body = json.dumps(obj).encode()
        self.p.stdin.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)
        self.p.stdin.flush()

    def recv(self):
        length = None
        while True:
            line = self.p.stdout.readline()
            if not line:
                raise SystemExit("lsyc lsp closed its output")
            line = line.strip()
            if not line:
                break
            name, _, value = line.partition(b":")
            if name.lower() == b"content-length":
                length = int(value)
        return json.loads(self.p.stdout.read(length))

    def request(self, method, params):
        self.id += 1
        self.send({"jsonrpc": "2.0", "id": self.id, "method": method, "params": params})
        while True:
            m = self.recv()
            if m.get("id") == self.id:
                return m["result"]

    def notify(self, method, params):
        self.send({"jsonrpc": "2.0", "method": method, "params": params})

    def wait_for(self, method):
        while True:
            m = self.recv()
            if m.get("method") == method:
                return m["params"]


def utf16_index(line, character):
    """The Python index of a UTF-16 column in a line."""
    units = 0
    for i, ch in enumerate(line):
        if units >= character:
            return i
        units += 2 if ord(ch) > 0xFFFF else 1
    return len(line)


def markdown(text):
    """The little markdown hover texts use: code fences, `code`, paragraphs."""
    out = []
    for i, part in enumerate(re.split(r"```lsy\n(.*?)\n```", text, flags=re.S)):
        if i % 2:
            out.append(f"<pre class=code>{html.escape(part)}</pre>")
        else:
            for para in part.strip().split("\n\n"):
                if para.strip():
                    p = html.escape(para)
                    p = re.sub(r"`([^`]+)`", r"<code>\1</code>", p)
                    out.append(f"<p>{p}</p>")
    return "\n".join(out)


def main():
    lsyc = sys.argv[1] if len(sys.argv) > 1 else "lsyc"
    out = pathlib.Path(sys.argv[2] if len(sys.argv) > 2 else "lsp-session.html")
    text = (ROOT / "lang-examples/monopodial-tree.lsy").read_text()
    # Three mistakes typed into the gallery program.
    text = text.replace("B(l * r2, w * wr)]/(d)", "B(l * r3, w * wr)]/(d)")
    text = text.replace("C(l * r1, w * wr);\n    C", "C(l * r1);\n    C")
    text = text.replace("rate\n", "rate\nconst spare = 2;\n", 1)
    uri = "file:///home/you/monopodial-tree.lsy"
    c = Client(lsyc)
    c.request("initialize", {"processId": None, "rootUri": None, "capabilities": {}})
    c.notify("initialized", {})
    c.notify("textDocument/didOpen", {"textDocument": {"uri": uri, "languageId": "lsy", "version": 1, "text": text}})
    diags = c.wait_for("textDocument/publishDiagnostics")["diagnostics"]
    lines = text.split("\n")
    hover_line = next(i for i, l in enumerate(lines) if l.lstrip().startswith("B(l, w)"))
    hover_col = lines[hover_line].index("r2")
    hover = c.request("textDocument/hover", {"textDocument": {"uri": uri}, "position": {"line": hover_line, "character": hover_col}})
    c.request("shutdown", None)
    c.notify("exit", None)

    # Marks per line: (start, end, class) in Python indices.
    marks = {}
    for d in diags:
        r = d["range"]
        cls = "err" if d.get("severity") == 1 else "warn"
        for ln in range(r["start"]["line"], r["end"]["line"] + 1):
            line = lines[ln] if ln < len(lines) else ""
            a = utf16_index(line, r["start"]["character"]) if ln == r["start"]["line"] else 0
            b = utf16_index(line, r["end"]["character"]) if ln == r["end"]["line"] else len(line)
            marks.setdefault(ln, []).append((a, max(b, a + 1), cls))
    hr = hover["range"]
    marks.setdefault(hr["start"]["line"], []).append(
        (utf16_index(lines[hr["start"]["line"]], hr["start"]["character"]), utf16_index(lines[hr["start"]["line"]], hr["end"]["character"]), "hov")
    )

    first = 7  # show the program from its constants on
    rows = []
    for ln in range(first, len(lines)):
        line = lines[ln]
        cuts = sorted(marks.get(ln, []))
        s, pos = "", 0
        for a, b, cls in cuts:
            if a < pos:
                continue
            s += html.escape(line[pos:a]) + f"<span class={cls}>" + html.escape(line[a:b] or " ") + "</span>"
            pos = b
        s += html.escape(line[pos:])
        if ln == hr["start"]["line"]:
            s += f"<div class=hover style='left: calc({utf16_index(line, hr['start']['character'])}ch + 4.2em)'>{markdown(hover['contents']['value'])}</div>"
        s = re.sub(r"(//[^<]*)$", r"<span class=cm>\1</span>", s)
        rows.append(f"<div class=row><span class=ln>{ln + 1}</span><span class=tx>{s}</span></div>")

    problems = []
    for d in diags:
        r = d["range"]["start"]
        icon = "✖" if d.get("severity") == 1 else "⚠"
        cls = "err" if d.get("severity") == 1 else "warn"
        msg = html.escape(d["message"].split("\n")[0])
        related = "".join(
            f"<div class=rel>↳ {html.escape(x['message'])} [Ln {x['location']['range']['start']['line'] + 1}]</div>"
            for x in d.get("relatedInformation", [])
        )
        problems.append(
            f"<div class=prob><span class='{cls}i'>{icon}</span> {msg} <span class=src>lsyc({d['code']})</span> "
            f"<span class=pos>[Ln {r['line'] + 1}, Col {r['character'] + 1}]</span>{related}</div>"
        )

    page = f"""<!doctype html><meta charset=utf-8><title>lsyc lsp session</title>
<style>
body {{ margin: 0; background: #1e1e1e; color: #d4d4d4; font: 14px/1.5 'DejaVu Sans Mono', monospace; }}
.bar {{ background: #2d2d2d; color: #ccc; padding: 6px 14px; font: 13px sans-serif; }}
.bar b {{ color: #fff; }}
.code {{ padding: 8px 0 7.5em; }}
.row {{ white-space: pre; position: relative; }}
.ln {{ display: inline-block; width: 3em; text-align: right; color: #858585; margin-right: 1.2em; }}
.cm {{ color: #6a9955; }}
.err {{ text-decoration: underline wavy #f14c4c; text-underline-offset: 3px; }}
.warn {{ text-decoration: underline wavy #cca700; text-underline-offset: 3px; }}
.hov {{ background: #264f78; }}
.hover {{ position: absolute; top: 1.6em; z-index: 2; white-space: normal; width: 30em; background: #252526;
  border: 1px solid #454545; padding: 2px 10px; font: 13px/1.45 sans-serif; box-shadow: 0 2px 8px #000a; }}
.hover pre.code {{ font: 13px 'DejaVu Sans Mono', monospace; color: #9cdcfe; margin: 6px 0; padding: 0; }}
.hover code {{ font-family: 'DejaVu Sans Mono', monospace; color: #ce9178; }}
.panel {{ border-top: 1px solid #444; background: #1e1e1e; padding: 4px 14px; font: 13px/1.6 sans-serif; }}
.panel h3 {{ font: bold 11px sans-serif; letter-spacing: .05em; color: #ccc; margin: 4px 0; }}
.erri {{ color: #f14c4c; }} .warni {{ color: #cca700; }}
.src, .pos {{ color: #999; }}
.rel {{ margin-left: 2.2em; color: #aaa; }}
.note {{ color: #888; font: 12px sans-serif; padding: 6px 14px; }}
</style>
<div class=bar><b>monopodial-tree.lsy</b> — diagnostics and hover as <code>lsyc lsp</code> sent them</div>
<div class=code>{''.join(rows)}</div>
<div class=panel><h3>PROBLEMS</h3>{''.join(problems)}</div>
<div class=note>Rendered by editors/demo/session.py from a real session with <code>lsyc lsp</code>: the squiggles are the ranges of the published diagnostics, the box is the hover over <code>r2</code>. Not a screenshot of VS Code.</div>
"""
    out.write_text(page)
    print(f"wrote {out} ({len(diags)} diagnostics)")


if __name__ == "__main__":
    main()
