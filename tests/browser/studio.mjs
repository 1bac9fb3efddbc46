// Browser tests of `lsyc studio`, in headless Chromium driven by playwright-core.
//
//   node studio.mjs LSYC_BINARY WORK_DIR
//
// WORK_DIR holds copies of the programs (monopodial-tree.lsy, palm.lsy), which
// the test edits and saves; screenshots are written there too. Each program is
// opened in its own `lsyc studio FILE --port 0 --no-open`. Prints one JSON line
// of measured round trips at the end; exits non-zero on the first failure.
import { chromium } from "playwright-core";
import { spawn } from "node:child_process";
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { createInterface } from "node:readline";

const [lsyc, work] = process.argv.slice(2);
if (!lsyc || !work) {
  console.error("usage: node studio.mjs LSYC_BINARY WORK_DIR");
  process.exit(2);
}
const CHROMIUM = process.env.CHROMIUM || "/usr/bin/chromium";
const TIMEOUT = 60_000;

function check(cond, what) {
  if (!cond) throw new Error(`failed: ${what}`);
  console.log(`ok: ${what}`);
}

/// Starts the studio on FILE; resolves with the process and its address.
function studio(file) {
  const child = spawn(lsyc, ["studio", file, "--port", "0", "--no-open"], {
    stdio: ["ignore", "pipe", "inherit"],
  });
  return new Promise((resolve, reject) => {
    const lines = createInterface({ input: child.stdout });
    lines.once("line", (line) => {
      const m = /^lsyc studio: (http:\/\/127\.0\.0\.1:\d+\/)$/.exec(line);
      if (m) resolve({ child, url: m[1] });
      else reject(new Error(`unexpected first line: ${line}`));
    });
    child.once("exit", (code) => reject(new Error(`lsyc studio exited with ${code}`)));
  });
}

const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length ? s[Math.floor(s.length / 2)] : null;
};

async function openPage(browser, url, errors) {
  const page = await browser.newPage({ viewport: { width: 1400, height: 860 } });
  page.setDefaultTimeout(TIMEOUT);
  page.on("console", (m) => {
    if (m.type() === "error") errors.push(`console: ${m.text()}`);
  });
  page.on("pageerror", (e) => errors.push(`page error: ${e.message}`));
  await page.goto(url);
  await page.waitForSelector("[data-role=drawing] svg");
  await page.evaluate(() => window.lsycStudio.idle());
  return page;
}

const idle = (page) => page.evaluate(() => window.lsycStudio.idle());
const source = (page) => page.evaluate(() => window.lsycStudio.getSource());
const drawing = (page) => page.evaluate(() => document.querySelector("[data-role=drawing] svg").outerHTML);

/// A gallery program: type, break and fix, slide a constant, step, save, reload.
async function gallery(browser, errors, timings) {
  const file = join(work, "monopodial-tree.lsy");
  const original = readFileSync(file, "utf8");
  const { child, url } = await studio(file);
  try {
    const page = await openPage(browser, url, errors);
    check((await source(page)) === original, "the editor holds the file");
    check((await page.$$("[data-role=diagnostics] > *")).length === 0, "no diagnostics at first");
    const first = await drawing(page);
    check(first.includes("<path"), "the drawing has paths");

    // Type at the end of the program: a new constant gets a slider.
    await page.click("[data-role=editor] .cm-content");
    await page.keyboard.press("Control+End");
    await page.keyboard.type("\nconst typed = 4;");
    await idle(page);
    await page.waitForSelector("input[data-role=const][data-name=typed]");
    check((await source(page)).endsWith("\nconst typed = 4;"), "typing edits the program");
    await page.waitForSelector("[data-role=diagnostics] [data-code=W0101]");
    check(true, "an unused constant is a warning W0101 in the list");
    await page.waitForSelector(".cm-lintRange-warning");
    check(true, "the warning is underlined in the editor");

    // Hover a use of `r2`: the language server's answer in a tooltip.
    const lineText = await page.locator(".cm-content .cm-line", { hasText: "A(l, w) ->" }).first().textContent();
    const col = lineText.indexOf("r2") + 1;
    const xy = await page.evaluate(({ col, text }) => {
      const line = [...document.querySelectorAll(".cm-content .cm-line")].find((l) => l.textContent === text);
      const walker = document.createTreeWalker(line, NodeFilter.SHOW_TEXT);
      let node;
      let left = col;
      while ((node = walker.nextNode())) {
        if (left <= node.length) break;
        left -= node.length;
      }
      const range = document.createRange();
      range.setStart(node, left - 1);
      range.setEnd(node, left);
      const r = range.getBoundingClientRect();
      return { x: r.left + r.width / 2, y: r.top + r.height / 2 };
    }, { col, text: lineText });
    await page.mouse.move(xy.x, xy.y);
    await page.waitForSelector(".cm-tooltip-hover .hover");
    const tip = await page.$eval(".cm-tooltip-hover .hover", (e) => e.textContent);
    check(/r2/.test(tip) && /0\.6/.test(tip), `hovering r2 shows the language server's hover (${tip.replace(/\s+/g, " ").slice(0, 60)}…)`);
    await page.screenshot({ path: join(work, "studio-hover.png") });
    await page.mouse.move(5, 5);

    // Break the program, then fix it.
    await page.click("[data-role=editor] .cm-content");
    await page.keyboard.press("Control+End");
    await page.keyboard.type(" typed(");
    await idle(page);
    await page.waitForSelector("[data-role=diagnostics] [data-code^=E]");
    const codes = await page.$$eval("[data-role=diagnostics] > *", (l) => l.map((e) => e.dataset.code));
    check(codes.some((c) => c.startsWith("E")), `a broken program shows error codes (${codes.join(" ")})`);
    check(await page.$(".cm-lintRange-error"), "the error is marked in the editor");
    check((await drawing(page)) === first, "a broken program keeps the last good drawing");
    for (let i = 0; i < " typed(".length; i++) await page.keyboard.press("Backspace");
    await idle(page);
    await page.waitForFunction(() => !document.querySelector("[data-role=diagnostics] [data-code^=E]"));
    check(true, "fixing the program clears its errors");

    // Slide a constant: the drawing follows while sliding; release writes it.
    const slider = "input[data-role=const][data-name=r2]";
    await page.waitForSelector(slider);
    const before = await drawing(page);
    for (const v of ["0.7", "0.8", "0.9"]) {
      await page.$eval(slider, (s, v) => {
        s.value = v;
        s.dispatchEvent(new Event("input", { bubbles: true }));
      }, v);
    }
    await idle(page);
    check((await drawing(page)) !== before, "sliding r2 redraws");
    check((await source(page)).includes("const r2 = 0.6;"), "sliding does not write the source yet");
    await page.$eval(slider, (s) => s.dispatchEvent(new Event("change", { bubbles: true })));
    await page.waitForFunction(() => window.lsycStudio.getSource().includes("const r2 = 0.9; // contraction ratio for branches"));
    check(true, "releasing writes r2 = 0.9 into the source, its comment kept");
    await idle(page);

    // Step through growth.
    const max = Number(await page.$eval("input[data-role=step]", (s) => s.max));
    check(max === 10, `the step slider goes to derive (${max})`);
    for (const k of [1, 2, 3]) {
      await page.$eval("input[data-role=step]", (s, k) => {
        s.value = String(k);
        s.dispatchEvent(new Event("input", { bubbles: true }));
      }, k);
      await idle(page);
    }
    check(await page.$("[data-role=drawing].stepping svg.previous"), "step 3 draws step 2 over it, the new modules marked");
    await page.click("[data-role=show-string]");
    await page.waitForFunction(() => document.querySelector("[data-role=string]").textContent.length > 0);
    const str = await page.$eval("[data-role=string]", (e) => e.textContent);
    check(/A\(/.test(str) && /B\(/.test(str), "the derived string of step 3 is shown");
    await page.screenshot({ path: join(work, "gallery-step.png") });
    await page.$eval("input[data-role=step]", (s) => {
      s.value = s.max;
      s.dispatchEvent(new Event("input", { bubbles: true }));
    });
    await idle(page);

    // Edit → drawing latency: replace the text several times.
    const text = await source(page);
    for (let i = 0; i < 8; i++) {
      await page.evaluate((t) => window.lsycStudio.setSource(t), text.replace("const a0 = 45;", `const a0 = ${40 + i};`));
      await idle(page);
    }
    timings.gallery_edit_ms = median(await page.evaluate(() => window.lsycStudio.timings.edit.slice(-8)));

    // Export: the drawing as the command line writes it.
    const [png] = await Promise.all([page.waitForEvent("download"), page.click("[data-role=export-png]")]);
    const pngBytes = readFileSync(await png.path());
    check(png.suggestedFilename() === "monopodial-tree.png" && pngBytes.subarray(1, 4).toString() === "PNG", `export PNG (${pngBytes.length} bytes)`);
    const [glb] = await Promise.all([page.waitForEvent("download"), page.click("[data-role=export-glb]")]);
    check(readFileSync(await glb.path()).subarray(0, 4).toString() === "glTF", "export GLB");

    // Orbit the 3D tree: dragging the drawing turns the camera (`--view`).
    check(await page.$("[data-role=orbit]:not([hidden])"), "a 3D program shows its view");
    const viewBefore = await drawing(page);
    const v = await page.locator("[data-role=view]").boundingBox();
    await page.mouse.move(v.x + v.width / 2, v.y + v.height / 2);
    await page.mouse.down();
    for (let i = 1; i <= 6; i++) await page.mouse.move(v.x + v.width / 2 + i * 10, v.y + v.height / 2 + i * 2);
    await page.mouse.up();
    await idle(page);
    const angle = await page.$eval("[data-role=view-angle]", (e) => e.value);
    check(angle === "view 0°, 26°", `orbiting sets the view (${angle})`);
    check((await drawing(page)) !== viewBefore, "orbiting redraws");
    await page.click("[data-role=reset-view]");
    await idle(page);

    // Save: the file on disk is the editor's text.
    await page.click("[data-role=save]");
    await page.waitForFunction(() => document.querySelector("[data-role=status]").textContent.startsWith("saved"));
    const saved = readFileSync(file, "utf8");
    check(saved === (await source(page)), "save writes the editor's text");

    // Another editor changes the file: the page (without unsaved edits) reloads.
    const other = saved.replace("const d = 137.5;", "const d = 120;");
    writeFileSync(file, other);
    await page.waitForFunction((t) => window.lsycStudio.getSource() === t, other);
    check(true, "a change on disk reloads a page without unsaved edits");

    // A second tab and a reloaded page draw (each page has its own session).
    const tab = await openPage(browser, url, errors);
    check(await tab.$("[data-role=drawing] svg path"), "a second tab draws");
    await tab.close();
    await page.reload();
    await page.waitForSelector("[data-role=drawing] svg path", { state: "attached" });
    await idle(page);
    check(true, "a reloaded page draws");

    // With unsaved edits, it asks instead.
    await page.evaluate(() => window.lsycStudio.setSource(window.lsycStudio.getSource() + "\n// mine"));
    writeFileSync(file, other + "\n// theirs");
    await page.waitForSelector("[data-role=disk-changed]:not([hidden])");
    check((await source(page)).endsWith("// mine"), "unsaved edits are kept and the page asks");
    // Saving now would write over the other editor's change: refused, and said.
    await page.click("[data-role=save]");
    await page.waitForFunction(() => document.querySelector("[data-role=status]").textContent.startsWith("not saved"));
    const message = await page.$eval("[data-role=disk-message]", (e) => e.textContent);
    check(message.startsWith("Not saved"), `the bar says the save was refused (${message})`);
    check(readFileSync(file, "utf8") === other + "\n// theirs", "the file changed on disk is not overwritten");
    await page.screenshot({ path: join(work, "gallery.png") });
    await page.close();
  } finally {
    child.kill();
  }
}

/// The palm scene: drag the top of the trunk and watch the crown follow.
async function palm(browser, errors, timings) {
  const file = join(work, "palm.lsy");
  const original = readFileSync(file, "utf8");
  const { child, url } = await studio(file);
  try {
    const page = await openPage(browser, url, errors);
    const layers = await page.$$eval("[data-role=drawing] svg g.guide-content", (l) => l.length);
    check(layers === 11, `the drawing has one layer per guide (${layers})`);
    check(await page.$("[data-role=drawing] svg polygon.guide"), "guide outlines are drawn");
    const handles = await page.$$eval("[data-vertex]", (l) => l.map((e) => e.dataset.vertex));
    check(handles.includes("trunk3.v2") && handles.includes("frond4.v9"), `a handle per guide vertex (${handles.length})`);

    // Pin the lowest trunk guide, then drag the top of the trunk.
    for (const v of ["trunk1.v0", "trunk1.v1", "trunk1.v2", "trunk1.v3"]) {
      const b = await page.locator(`[data-vertex="${v}"]`).first().boundingBox();
      await page.keyboard.down("Shift");
      await page.mouse.click(b.x + b.width / 2, b.y + b.height / 2);
      await page.keyboard.up("Shift");
    }
    check((await page.$$(".handle.pinned")).length === 4, "shift-click pins four vertices");
    check(await page.$('[data-vertex="trunk1.v0"][data-pinned=true]'), "a pinned vertex says so");
    // Alt-click two vertices: a stiff spring between them; again: gone.
    const altClick = async (v) => {
      const b = await page.locator(`[data-vertex="${v}"]`).first().boundingBox();
      await page.keyboard.down("Alt");
      await page.mouse.click(b.x + b.width / 2, b.y + b.height / 2);
      await page.keyboard.up("Alt");
    };
    await altClick("trunk2.v1");
    await altClick("trunk3.v0");
    check(await page.$('line.stiff[data-stiff="trunk2.v1=trunk3.v0"]'), "alt-click two vertices adds a stiff spring");
    await altClick("trunk2.v1");
    await altClick("trunk3.v0");
    check(!(await page.$("line.stiff")), "alt-clicking them again removes it");
    const before = await drawing(page);
    const crownBefore = await page.$eval("[data-role=drawing] svg g[data-guide=frond4]", (g) => g.innerHTML);
    const h = page.locator('[data-vertex="trunk3.v2"]').last();
    const b = await h.boundingBox();
    const x0 = b.x + b.width / 2;
    const y0 = b.y + b.height / 2;
    await page.mouse.move(x0, y0);
    await page.mouse.down();
    for (let i = 1; i <= 12; i++) {
      await page.mouse.move(x0 + i * 5, y0 + i * 1.5);
      await page.waitForTimeout(30);
    }
    await page.mouse.up();
    await idle(page);
    await page.waitForFunction((o) => window.lsycStudio.getSource() !== o, original);
    await idle(page);
    const after = await source(page);
    check(after !== original, "releasing the vertex writes new polygons");
    check(after.includes("// The palm of Beneš"), "the comments are kept");
    const trunk3 = (t) => t.split("\n").find((l) => l.includes("polygon (53.8, 237.4)") || (l.includes("polygon") && t.indexOf(l) > t.indexOf("guide trunk3")));
    check(trunk3(after) !== trunk3(original), "trunk3's polygon changed");
    check((await drawing(page)) !== before, "the drawing changed");
    const crownAfter = await page.$eval("[data-role=drawing] svg g[data-guide=frond4]", (g) => g.innerHTML);
    check(crownAfter !== crownBefore, "the crown followed the trunk");
    const drags = await page.evaluate(() => window.lsycStudio.timings.drag);
    check(drags.length >= 2, `the drawing was redrawn while dragging (${drags.length} times)`);
    timings.palm_drag_ms = median(drags);
    timings.palm_drags = drags.length;
    const status = await page.$eval("[data-role=status]", (e) => e.textContent);
    check(/scene Palm: 11 systems/.test(status), `the status line shows the stats (${status.slice(0, 60)}…)`);

    // Edit → drawing latency on the palm.
    const text = await source(page);
    for (let i = 0; i < 6; i++) {
      await page.evaluate((t) => window.lsycStudio.setSource(t), text.replace("const NEAR = 6;", `const NEAR = ${5 + i * 0.2};`));
      await idle(page);
    }
    timings.palm_edit_ms = median(await page.evaluate(() => window.lsycStudio.timings.edit.slice(-6)));
    await page.evaluate((t) => window.lsycStudio.setSource(t), text);
    await idle(page);

    await page.click("[data-role=save]");
    await page.waitForFunction(() => document.querySelector("[data-role=status]").textContent.startsWith("saved"));
    check(readFileSync(file, "utf8") === text, "save writes the dragged polygons to the file");
    await page.click("[data-role=fit]");
    await idle(page);
    await page.screenshot({ path: join(work, "palm.png") });
    await page.close();
  } finally {
    child.kill();
  }
}

/// The guided tree: 1.25 MB of drawing; a drag redraws only the layers it changed.
async function tree(browser, errors, timings) {
  const file = join(work, "tree.lsy");
  const { child, url } = await studio(file);
  try {
    const page = await openPage(browser, url, errors);
    const layers = await page.$$eval("[data-role=drawing] svg g.guide-content", (l) => l.length);
    check(layers === 10, `the tree has one layer per guide (${layers})`);
    const b = await page.locator('[data-vertex="trunk.v0"]').first().boundingBox();
    await page.keyboard.down("Shift");
    await page.mouse.click(b.x + b.width / 2, b.y + b.height / 2);
    await page.keyboard.up("Shift");
    // The whole trunk held, as a person holds it (its other corners are shared
    // with the limbs' handles, so they are pinned through the page's API).
    await page.evaluate(() => {
      for (let i = 1; i < 12; i++) window.lsycStudio.togglePin(`trunk.v${i}`);
    });
    check((await page.$$('[data-vertex^="trunk."][data-pinned=true]')).length === 12, "the trunk's twelve vertices are pinned");
    const trunkBefore = await page.$eval("[data-role=drawing] svg g[data-guide=trunk]", (g) => g.innerHTML);
    const limbBefore = await page.$eval("[data-role=drawing] svg g[data-guide=limbR1]", (g) => g.innerHTML);
    const trunkNode = await page.$("[data-role=drawing] svg g[data-guide=trunk]");
    const h = page.locator('[data-vertex="limbR1.v2"]').last();
    const hb = await h.boundingBox();
    const x0 = hb.x + hb.width / 2;
    const y0 = hb.y + hb.height / 2;
    await page.mouse.move(x0, y0);
    await page.mouse.down();
    await idle(page);
    for (let i = 1; i <= 16; i++) {
      await page.mouse.move(x0 + i * 2, y0 - i);
      await page.waitForTimeout(40);
    }
    await idle(page);
    const status = await page.$eval("[data-role=status]", (e) => e.textContent);
    const sent = /sent (\d+) of 10 layers/.exec(status);
    check(sent && Number(sent[1]) < 10, `a move sends only the layers that changed (${sent && sent[0]})`);
    check(await trunkNode.evaluate((n) => n.isConnected), "the unchanged trunk layer stays on the page as it was");
    check((await page.$eval("[data-role=drawing] svg g[data-guide=trunk]", (g) => g.innerHTML)) === trunkBefore, "the trunk is unchanged");
    check((await page.$eval("[data-role=drawing] svg g[data-guide=limbR1]", (g) => g.innerHTML)) !== limbBefore, "the dragged limb redrew");
    await page.mouse.up();
    await idle(page);
    await page.waitForFunction(() => window.lsycStudio.getSource().includes("limbR1"));
    await idle(page);
    const t = await page.evaluate(() => window.lsycStudio.timings);
    // The last drag reply is the release; the moves before it.
    const moves = t.drag.slice(1, -1);
    check(moves.length >= 3, `the tree was redrawn while dragging (${moves.length} times)`);
    timings.tree_drag_ms = median(moves);
    timings.tree_drag_page_ms = median(t.page.slice(1, -1));
    timings.tree_drags = moves.length;
    await page.screenshot({ path: join(work, "tree.png") });
    await page.close();
  } finally {
    child.kill();
  }
}

const browser = await chromium.launch({
  executablePath: CHROMIUM,
  headless: true,
  args: [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
  ],
});
const errors = [];
const timings = {};
let failed = false;
try {
  await gallery(browser, errors, timings);
  await palm(browser, errors, timings);
  await tree(browser, errors, timings);
  check(errors.length === 0, `no console errors${errors.length ? ": " + errors.join("; ") : ""}`);
} catch (e) {
  console.error(e.stack || String(e));
  failed = true;
} finally {
  await browser.close();
}
console.log(JSON.stringify({ timings }));
process.exit(failed ? 1 : 0);
