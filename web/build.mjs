// Builds the studio's page into dist/ (committed): bundles src/studio.js with
// esbuild, copies the HTML and CSS, and writes dist/source-hash.txt, the hash
// of the sources that a Rust test recomputes to catch a stale bundle.
// Run with `npm ci && npm run build` in web/.
import * as esbuild from "esbuild";
import { copyFileSync, mkdirSync, readFileSync, readdirSync, statSync, writeFileSync } from "node:fs";
import { join, relative } from "node:path";

const here = new URL(".", import.meta.url).pathname;
const dist = join(here, "dist");
mkdirSync(dist, { recursive: true });

await esbuild.build({
  entryPoints: [join(here, "src/studio.js")],
  bundle: true,
  minify: true,
  format: "esm",
  target: "es2020",
  legalComments: "eof",
  outfile: join(dist, "studio.js"),
  logLevel: "warning",
});
copyFileSync(join(here, "src/index.html"), join(dist, "index.html"));
copyFileSync(join(here, "src/studio.css"), join(dist, "studio.css"));
writeFileSync(join(dist, "source-hash.txt"), sourceHash() + "\n");

/// FNV-1a (64 bits) over the sources, in sorted path order: for each file its
/// path (relative to web/, with /), a NUL, its bytes, a NUL. Not a defence
/// against anyone: a check that the bundle was rebuilt after an edit.
function sourceHash() {
  const files = ["build.mjs", "package-lock.json"];
  const walk = (dir) => {
    for (const name of readdirSync(dir)) {
      const p = join(dir, name);
      if (statSync(p).isDirectory()) walk(p);
      else files.push(relative(here, p).split("\\").join("/"));
    }
  };
  walk(join(here, "src"));
  files.sort();
  let h = 0xcbf29ce484222325n;
  const eat = (bytes) => {
    for (const b of bytes) {
      h ^= BigInt(b);
      h = (h * 0x100000001b3n) & 0xffffffffffffffffn;
    }
  };
  for (const f of files) {
    eat(Buffer.from(f, "utf8"));
    eat([0]);
    eat(readFileSync(join(here, f)));
    eat([0]);
  }
  return h.toString(16).padStart(16, "0");
}
