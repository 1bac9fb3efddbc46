//! The page's assets, compiled into the binary from `web/dist/` (built from
//! `web/src/` by `npm run build` in `web/`, and committed, so that building
//! lsyc needs no Node). `SOURCE_HASH` is the hash of the sources the bundle
//! was built from; a test recomputes it from `web/src/` to catch a stale bundle.
//!
//! Owns: the mapping from URL paths to bytes and content types.

/// The hash of `web/src/**` and `web/package-lock.json` the bundle was built
/// from, as `web/build.mjs` wrote it.
pub const SOURCE_HASH: &str = include_str!("../../web/dist/source-hash.txt");

const INDEX: &str = include_str!("../../web/dist/index.html");
const SCRIPT: &str = include_str!("../../web/dist/studio.js");
const STYLE: &str = include_str!("../../web/dist/studio.css");

/// The bytes and content type of an asset.
pub fn get(path: &str) -> Option<(&'static [u8], &'static str)> {
    Some(match path {
        "/" | "/index.html" => (INDEX.as_bytes(), "text/html; charset=utf-8"),
        "/studio.js" => (SCRIPT.as_bytes(), "text/javascript; charset=utf-8"),
        "/studio.css" => (STYLE.as_bytes(), "text/css; charset=utf-8"),
        _ => return None,
    })
}
