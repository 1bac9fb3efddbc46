#!/usr/bin/env python3
"""Generate the held-out set of classic L-system line drawings (see README.md).

Standard library only, and deliberately independent of lsyc: it has its own D0L
rewriter and its own 2D turtle, so that a bug shared with lsyc's interpreter cannot
hide in the test data. Run from anywhere:

    python3 gen.py            # (re)writes every SVG and manifest.json beside this file
    python3 gen.py --check    # recomputes everything and fails if a file would change

The output is a pure function of this file: every random draw comes from a
random.Random seeded with a fixed string, so running it again gives identical bytes.

Turtle (ABOP conventions, y up): letters listed in a system's `draw` draw a step of
length 1, `f` moves one step without drawing, `+` turns left (counter-clockwise) by
delta, `-` turns right, `[` and `]` push and pop position and heading, every other
letter does nothing. A world point (x, y) becomes the SVG point (10 x, -10 y) in the
`clean` variant (step length 10, y flipped as SVG's y points down).
"""

import json
import math
import os
import random
import re
import sys
from fractions import Fraction

HERE = os.path.dirname(os.path.abspath(__file__))
STEP = 10  # SVG length of one turtle step in the clean variant
SEED = "lsyc-classic-lines-v1"  # changing it changes every non-clean file
VARIANTS = ["clean", "rotated", "jittered", "split", "shuffled"]
DECIMALS = {"clean": 6, "rotated": 4, "jittered": 3, "split": 4, "shuffled": 4}
JITTER_FRACTION = 0.002  # of the bounding-box diagonal of the drawn level ...
JITTER_MAX_STEPS = 0.25  # ... but never more than a quarter of one step (long thin
# drawings such as the tribonacci stair would otherwise be jittered beyond recognition)

# The classic systems. `rules` use ASCII '-' for the minus sign. `draw` lists the
# letters that draw a step; all other letters but 'f' (move) and the turtle symbols
# + - [ ] only rewrite.
SYSTEMS = [
    dict(
        name="sierpinski-arrowhead",
        title="Sierpinski arrowhead curve",
        source="ABOP fig. 1.10b (Prusinkiewicz & Lindenmayer 1990), written with "
        "A and B for F_r and F_l as in Wikipedia: Sierpinski triangle (arrowhead construction)",
        axiom="A",
        rules={"A": "B-A-B", "B": "A+B+A"},
        draw="AB",
        delta=60,
        heading=0,
        n=6,
    ),
    dict(
        name="sierpinski-carpet",
        title="Sierpinski carpet (F/G form, G draws)",
        source="common D0L form F -> F+F-F-F-G+F+F+F-F, G -> GGG, delta 90 "
        "(found in many L-system collections); here G draws, "
        "so the holes are crossed by G lines, unlike L. Riddle's variant where G "
        "is an invisible move",
        axiom="F",
        rules={"F": "F+F-F-F-G+F+F+F-F", "G": "GGG"},
        draw="FG",
        delta=90,
        heading=0,
        n=3,
    ),
    dict(
        name="cesaro",
        title="Cesaro curve (85 degree Koch variant)",
        source="E. Cesaro 1905 (Mandelbrot, The Fractal Geometry of Nature, "
        "pp. 64-65); the common L-system form F -> F+F--F+F, delta 85, axiom F "
        "(one side, not the four-sided torn square)",
        axiom="F",
        rules={"F": "F+F--F+F"},
        draw="F",
        delta=85,
        heading=0,
        n=4,
    ),
    dict(
        name="flowsnake",
        title="Gosper curve (flowsnake)",
        source="Wikipedia: Gosper curve (A and B both draw); ABOP fig. 1.11a "
        "with F_l, F_r is its mirror image (+ and - swapped)",
        axiom="A",
        rules={"A": "A-B--B+A++AA+B-", "B": "+A-BB--B-A++A+B"},
        draw="AB",
        delta=60,
        heading=0,
        n=3,
    ),
    dict(
        name="levy-c",
        title="Levy C curve",
        source="Wikipedia: Levy C curve (L-system section)",
        axiom="F",
        rules={"F": "+F--F+"},
        draw="F",
        delta=45,
        heading=0,
        n=10,
    ),
    dict(
        name="pentigree",
        title="McWorter's pentigree",
        source="W. McWorter's pentigree; the common L-system form "
        "F -> +F++F----F--F++F++F-, delta 36, axiom F",
        axiom="F",
        rules={"F": "+F++F----F--F++F++F-"},
        draw="F",
        delta=36,
        heading=0,
        n=3,
    ),
    dict(
        name="plant-22",
        title="Bracketed plant, 22.5 degrees (ABOP fig. 1.24c)",
        source="ABOP fig. 1.24c (Prusinkiewicz & Lindenmayer 1990), drawn there "
        "at n = 4",
        axiom="F",
        rules={"F": "FF-[-F+F+F]+[+F-F-F]"},
        draw="F",
        delta=22.5,
        heading=90,
        n=3,
    ),
    dict(
        name="terdragon",
        title="Terdragon",
        source="Wikipedia: Dragon curve (Terdragon, L-system F -> F+F-F, 120 deg)",
        axiom="F",
        rules={"F": "F+F-F"},
        draw="F",
        delta=120,
        heading=0,
        n=6,
    ),
    dict(
        name="sierpinski-triangle",
        title="Sierpinski triangle",
        source="Wikipedia: L-system (example: Sierpinski triangle)",
        axiom="F-G-G",
        rules={"F": "F-G+F+G-F", "G": "GG"},
        draw="FG",
        delta=120,
        heading=0,
        n=5,
    ),
    dict(
        name="binary-tree",
        title="Fractal (binary) tree",
        source="Wikipedia: L-system (example: fractal (binary) tree, "
        "0 -> 1[0]0, 1 -> 11, '[' = push and turn left 45, ']' = pop and turn "
        "right 45), written with turtle letters: 0 = G, 1 = F, so G -> F[+G]-G, "
        "F -> FF; both draw a plain step (no leaf mark)",
        axiom="G",
        rules={"G": "F[+G]-G", "F": "FF"},
        draw="FG",
        delta=45,
        heading=90,
        n=7,
    ),
    dict(
        name="tribonacci",
        title="Tribonacci word as a three-direction staircase",
        source="the tribonacci (Rauzy) substitution 1 -> 12, 2 -> 13, 3 -> 1 "
        "(G. Rauzy 1982; Wikipedia: Rauzy fractal, stair construction) with "
        "letters A, B, C for 1, 2, 3, each a unit step in its own absolute "
        "direction 0, 120, 240 degrees (Rauzy's stair seen along the diagonal "
        "(1, 1, 1)); the turtle encoding (each letter's rule turns to the "
        "image letters' directions and back) is this set's own derivation",
        axiom="A",
        rules={"A": "A+B-", "B": "-A-C-", "C": "+A-"},
        draw="ABC",
        delta=120,
        heading=0,
        n=11,
    ),
    dict(
        name="bush-20",
        title="Bracketed bush with X apices, 20 degrees (ABOP fig. 1.24d)",
        source="ABOP fig. 1.24d (Prusinkiewicz & Lindenmayer 1990), drawn there "
        "at n = 7",
        axiom="X",
        rules={"X": "F[+X]F[-X]+X", "F": "FF"},
        draw="F",
        delta=20,
        heading=90,
        n=5,
    ),
    dict(
        name="hilbert",
        title="Hilbert curve",
        source="Wikipedia: Hilbert curve (L-system section, A/B written X/Y)",
        axiom="X",
        rules={"X": "+YF-XFX-FY+", "Y": "-XF+YFY+FX-"},
        draw="F",
        delta=90,
        heading=0,
        n=5,
    ),
    dict(
        name="moore",
        title="Moore curve",
        source="Wikipedia: Moore curve (L-system section)",
        axiom="LFL+F+LFL",
        rules={"L": "-RF+LFL+FR-", "R": "+LF-RFR-FL+"},
        draw="F",
        delta=90,
        heading=0,
        n=3,
    ),
    dict(
        name="peano",
        title="Peano curve",
        source="G. Peano 1890; the usual L-system form with two node letters "
        "X, Y (as in many L-system collections); visits every point of a "
        "3^n x 3^n grid",
        axiom="X",
        rules={"X": "XFYFX+F+YFXFY-F-XFYFX", "Y": "YFXFY-F-XFYFX+F+YFXFY"},
        draw="F",
        delta=90,
        heading=0,
        n=3,
    ),
]


# ----------------------------------------------------------------------------
# D0L rewriting and the turtle


def derive(axiom, rules, n):
    s = axiom
    for _ in range(n):
        s = "".join(rules.get(c, c) for c in s)
    return s


def _unit(deg):
    """cos and sin of an exact angle in degrees, exact at multiples of 90."""
    d = deg % 360
    exact = {0: (1.0, 0.0), 90: (0.0, 1.0), 180: (-1.0, 0.0), 270: (0.0, -1.0)}
    if d in exact:
        return exact[d]
    r = math.radians(float(d))
    return math.cos(r), math.sin(r)


def interpret(word, draw, delta, heading):
    """Run the turtle over `word`.

    Returns (steps, strokes): `steps` is every drawn unit step in derivation order
    as ((x0, y0), (x1, y1)) in world coordinates (y up); `strokes` are the polylines
    of the clean drawing (a new one after each ']' and each 'f'), with consecutive
    collinear steps merged, as lists of world points.
    """
    delta = Fraction(delta).limit_denominator(1000)
    h = Fraction(heading).limit_denominator(1000) % 360
    x = y = 0.0
    stack = []
    steps = []
    strokes = []
    cur = None  # current stroke: list of points
    cur_h = None  # heading of its last segment
    trig = {}
    for c in word:
        if c in draw:
            if h not in trig:
                trig[h] = _unit(h)
            cx, sy = trig[h]
            nx, ny = x + cx, y + sy
            steps.append(((x, y), (nx, ny)))
            if cur is None:
                cur = [(x, y), (nx, ny)]
                strokes.append(cur)
            elif cur_h == h:
                cur[-1] = (nx, ny)
            else:
                cur.append((nx, ny))
            cur_h = h
            x, y = nx, ny
        elif c == "f":
            if h not in trig:
                trig[h] = _unit(h)
            cx, sy = trig[h]
            x, y = x + cx, y + sy
            cur = None
        elif c == "+":
            h = (h + delta) % 360
        elif c == "-":
            h = (h - delta) % 360
        elif c == "[":
            stack.append((x, y, h))
        elif c == "]":
            x, y, h = stack.pop()
            cur = None
        # every other letter does nothing
    return steps, strokes


def duplicate_steps(steps):
    """How many drawn steps lie on a step drawn before (either direction)."""
    seen = set()
    dup = 0
    for a, b in steps:
        ka = (round(a[0], 6), round(a[1], 6))
        kb = (round(b[0], 6), round(b[1], 6))
        k = (ka, kb) if ka <= kb else (kb, ka)
        if k in seen:
            dup += 1
        seen.add(k)
    return dup


# ----------------------------------------------------------------------------
# transforms and SVG output


def fmt(v, decimals):
    s = f"{v:.{decimals}f}"
    if "." in s:
        s = s.rstrip("0").rstrip(".")
    if s in ("-0", ""):
        s = "0"
    return s


def world_to_clean(p):
    return (STEP * p[0], -STEP * p[1])


def make_transform(rng):
    """A random similarity of the SVG plane: rotation, scale, translation."""
    # a generic angle: never within 2 degrees of a multiple of 15, so that no
    # variant is axis-aligned (or nearly so) by accident
    while True:
        rot = round(rng.uniform(0.0, 360.0), 3)
        off = rot % 15.0
        if 2.0 <= off <= 13.0:
            break
    scale = round(rng.uniform(0.5, 3.0), 4)
    tx = round(rng.uniform(-400.0, 400.0), 3)
    ty = round(rng.uniform(-400.0, 400.0), 3)
    return dict(rotation_deg=rot, scale=scale, translate=[tx, ty])


def apply(t, p):
    """Apply transform t to a clean SVG point p."""
    r = math.radians(t["rotation_deg"])
    c, s = math.cos(r) * t["scale"], math.sin(r) * t["scale"]
    return (c * p[0] - s * p[1] + t["translate"][0], s * p[0] + c * p[1] + t["translate"][1])


def world_matrix(t):
    """SVG matrix(a b c d e f) taking world coordinates (step 1, y up) to the file's
    user coordinates: x' = a x + c y + e, y' = b x + d y + f."""
    r = math.radians(t["rotation_deg"])
    c, s = math.cos(r) * t["scale"], math.sin(r) * t["scale"]
    # clean: (x, y) -> (STEP x, -STEP y); then [c -s; s c]
    a, b = STEP * c, STEP * s
    cc, d = STEP * s, -STEP * c
    return [round(v, 9) for v in (a, b, cc, d, t["translate"][0], t["translate"][1])]


IDENTITY = dict(rotation_deg=0.0, scale=1.0, translate=[0.0, 0.0])


def bbox(points):
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    return min(xs), min(ys), max(xs), max(ys)


def jitter_points(strokes, radius, rng):
    """Move every distinct vertex by an offset uniform in a disc of `radius`.

    A location shared by several strokes (a branch point, a crossing vertex) moves
    the same way in all of them, so the drawing stays connected."""
    moved = {}
    out = []
    for st in strokes:
        ns = []
        for p in st:
            k = (round(p[0], 6), round(p[1], 6))
            if k not in moved:
                rr = radius * math.sqrt(rng.random())
                a = rng.uniform(0.0, 2.0 * math.pi)
                moved[k] = (p[0] + rr * math.cos(a), p[1] + rr * math.sin(a))
            ns.append(moved[k])
        out.append(ns)
    return out


def svg_document(elements, points, comment, step_len):
    x0, y0, x1, y1 = bbox(points)
    diag = math.hypot(x1 - x0, y1 - y0) or 1.0
    m = 0.02 * diag
    sw = min(diag / 800.0, step_len / 8.0)  # only for viewing
    vb = " ".join(fmt(v, 3) for v in (x0 - m, y0 - m, x1 - x0 + 2 * m, y1 - y0 + 2 * m))
    head = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="{vb}">\n'
        f"<!-- {comment} -->\n"
        f'<g fill="none" stroke="black" stroke-width="{fmt(sw, 3)}" '
        'stroke-linecap="round" stroke-linejoin="round">\n'
    )
    return head + "\n".join(elements) + "\n</g>\n</svg>\n"


def polyline(pts, dec):
    return '<polyline points="' + " ".join(f"{fmt(x, dec)},{fmt(y, dec)}" for x, y in pts) + '"/>'


def segpath(a, b, dec):
    return f'<path d="M{fmt(a[0], dec)} {fmt(a[1], dec)}L{fmt(b[0], dec)} {fmt(b[1], dec)}"/>'


def render_variant(sysdef, variant, level_tag, level, steps, strokes, t, rng_level):
    """Returns (svg text, info dict) for one file."""
    dec = DECIMALS[variant]
    comment = (
        f"{sysdef['name']} level {level} ({level_tag}), variant {variant}; "
        "generated by tests/data/lines/classic/gen.py, not by lsyc"
    )
    info = {}
    if variant in ("clean", "rotated", "jittered"):
        pts = [[apply(t, world_to_clean(p)) for p in st] for st in strokes]
        if variant == "jittered":
            allp = [p for st in pts for p in st]
            x0, y0, x1, y1 = bbox(allp)
            radius = min(
                JITTER_FRACTION * math.hypot(x1 - x0, y1 - y0),
                JITTER_MAX_STEPS * STEP * t["scale"],
            )
            pts = jitter_points(pts, radius, rng_level)
            info["jitter_radius"] = round(radius, 6)
        elements = [polyline(st, dec) for st in pts]
        info["elements"] = len(elements)
        info["points"] = sum(len(st) for st in pts)
        allp = [p for st in pts for p in st]
    else:
        segs = [(apply(t, world_to_clean(a)), apply(t, world_to_clean(b))) for a, b in steps]
        if variant == "shuffled":
            rng_level.shuffle(segs)
            rev = 0
            out = []
            for a, b in segs:
                if rng_level.random() < 0.5:
                    out.append((b, a))
                    rev += 1
                else:
                    out.append((a, b))
            segs = out
            info["reversed"] = rev
        elements = [segpath(a, b, dec) for a, b in segs]
        info["elements"] = len(elements)
        info["points"] = 2 * len(elements)
        allp = [p for s in segs for p in s]
    return svg_document(elements, allp, comment, STEP * t["scale"]), info


def build():
    files = {}
    manifest = {
        "description": "Held-out classic L-system line drawings with their next level, "
        "generated by gen.py (own turtle, not lsyc). Never tune inference on these.",
        "generator": "tests/data/lines/classic/gen.py",
        "seed": SEED,
        "step_length_clean": STEP,
        "turtle": {
            "draw": "letters in the system's `draw` draw one step of length 1",
            "f": "move one step without drawing (starts a new stroke)",
            "+": "turn left (counter-clockwise, y up) by delta",
            "-": "turn right (clockwise, y up) by delta",
            "[": "push position and heading (the stroke goes on)",
            "]": "pop position and heading (starts a new stroke)",
            "other": "letters not in `draw` do nothing",
            "start": "turtle at (0, 0), heading `start_heading_deg` counter-clockwise from +x",
            "world_to_clean_svg": "(x, y) -> (10 x, -10 y)",
        },
        "variants": {
            "clean": "one <polyline> per stroke in derivation order (new stroke after "
            "each ']' and each 'f'), collinear consecutive steps merged, 6 decimals, "
            "step 10, no rotation",
            "rotated": "clean, then a random similarity (rotation, scale 0.5-3, "
            "translation), 4 decimals",
            "jittered": "rotated (own transform), then every distinct vertex moved by "
            "a uniform random offset in a disc of radius min(0.2% of that level's "
            "bounding-box diagonal, 1/4 step), 3 decimals; a location shared by "
            "several strokes moves once",
            "split": "one <path d='M x y L x y'> per unit step in derivation order, "
            "random similarity, 4 decimals",
            "shuffled": "split (own transform), then the paths in random order and "
            "each reversed with probability 1/2",
        },
        "transform_convention": "clean SVG point (x, y) -> (s (x cos r - y sin r) + tx, "
        "s (x sin r + y cos r) + ty) with r = rotation_deg (clockwise on screen, "
        "counter-clockwise in the y-up world); `world_matrix` is the SVG "
        "matrix(a b c d e f) from world coordinates (step 1, y up) straight to the "
        "file's coordinates. Level n and next share the transform of their variant.",
        "jitter_fraction_of_diagonal": JITTER_FRACTION,
        "jitter_max_fraction_of_step": JITTER_MAX_STEPS,
        "file_pattern": "NAME-VARIANT-n.svg (level n) and NAME-VARIANT-next.svg (level n + 1)",
        "counts": "steps: drawn unit steps; duplicate_steps: steps lying on an earlier "
        "step (Levy C and the 22.5 plant retrace some); elements: <polyline> or "
        "<path> elements in the file; points: coordinate pairs in the file",
        "systems": [],
    }
    for sd in SYSTEMS:
        levels = {}
        for tag, lv in (("n", sd["n"]), ("next", sd["n"] + 1)):
            word = derive(sd["axiom"], sd["rules"], lv)
            steps, strokes = interpret(word, sd["draw"], sd["delta"], sd["heading"])
            levels[tag] = (lv, word, steps, strokes)
        entry = {
            "name": sd["name"],
            "title": sd["title"],
            "source": sd["source"],
            "axiom": sd["axiom"],
            "rules": sd["rules"],
            "draw": sd["draw"],
            "delta_deg": sd["delta"],
            "start_heading_deg": sd["heading"],
            "n": sd["n"],
            "steps": {tag: len(levels[tag][2]) for tag in levels},
            "levels": {
                tag: {
                    "level": levels[tag][0],
                    "steps": len(levels[tag][2]),
                    "word_length": len(levels[tag][1]),
                    "clean_strokes": len(levels[tag][3]),
                    "clean_segments": sum(len(st) - 1 for st in levels[tag][3]),
                    "duplicate_steps": duplicate_steps(levels[tag][2]),
                }
                for tag in levels
            },
            "growth": round(len(levels["next"][2]) / len(levels["n"][2]), 4),
            "variants": {},
        }
        for var in VARIANTS:
            if var == "clean":
                t = dict(IDENTITY)
            else:
                t = make_transform(random.Random(f"{SEED}:{sd['name']}:{var}:transform"))
            ventry = dict(t)
            ventry["decimals"] = DECIMALS[var]
            ventry["world_matrix"] = world_matrix(t)
            ventry["jitter_radius"] = None
            ventry["files"] = {}
            for tag in ("n", "next"):
                lv, word, steps, strokes = levels[tag]
                rng = random.Random(f"{SEED}:{sd['name']}:{var}:{tag}")
                text, info = render_variant(sd, var, tag, lv, steps, strokes, t, rng)
                fname = f"{sd['name']}-{var}-{tag}.svg"
                files[fname] = text
                radius = info.pop("jitter_radius", None)
                if radius is not None:
                    if ventry["jitter_radius"] is None:
                        ventry["jitter_radius"] = {}
                    ventry["jitter_radius"][tag] = radius
                ventry["files"][tag] = dict(file=fname, **info)
            entry["variants"][var] = ventry
        manifest["systems"].append(entry)
    text = json.dumps(manifest, indent=2, ensure_ascii=True)
    # keep short lists of numbers on one line
    text = re.sub(r"\[\s+([-0-9., \n]*?)\s+\]", lambda m: "[" + " ".join(m.group(1).split()) + "]", text)
    files["manifest.json"] = text + "\n"
    return files


def main(argv):
    check = "--check" in argv
    files = build()
    changed = []
    for name, text in sorted(files.items()):
        path = os.path.join(HERE, name)
        old = None
        if os.path.exists(path):
            with open(path, encoding="utf-8") as fh:
                old = fh.read()
        if old != text:
            changed.append(name)
            if not check:
                with open(path, "w", encoding="utf-8", newline="\n") as fh:
                    fh.write(text)
    if check:
        if changed:
            print(f"{len(changed)} file(s) differ: {', '.join(changed[:10])}")
            return 1
        print(f"all {len(files)} files up to date")
        return 0
    print(f"wrote {len(changed)} of {len(files)} files")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
