//! The studio's HTTP server (tiny_http, on 127.0.0.1 only): the page's assets
//! from the binary, and a JSON API that the page calls with `fetch`.
//!
//! Routes: `GET /` and the assets; `GET /api/file` (the file's text and
//! version); `POST /api/run` and `POST /api/drag` (through the worker);
//! `POST /api/const` (a constant's value written into the source);
//! `POST /api/string` (the derived string of a step); `POST /api/save` (the
//! file written atomically); `POST /api/hover` and `POST /api/complete` (the
//! language server's answers at a place in the text); `POST /api/export`
//! (the drawing as SVG, PNG, OBJ or GLB).
//!
//! Runs and drags go to one worker thread through a one-place mailbox: a
//! newer request replaces a waiting older one (which is answered
//! `superseded`), and a result finished after a newer request arrived is
//! answered `superseded` too, so the page only ever draws the latest.
//!
//! Owns: sockets, the file on disk, threads. Must not run programs itself:
//! `protocol` does.

use super::assets;
use super::protocol::{self, Drag, DragSession, Program};
use serde::Deserialize;
use serde_json::{Value as Json, json};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Condvar, Mutex};

/// The largest request body read (a program is at most 64 MiB; the page
/// sends one program per request).
const MAX_BODY: u64 = 80 << 20;

/// The studio's server, bound and ready.
pub struct Studio {
    server: tiny_http::Server,
    state: Arc<State>,
    port: u16,
}

struct State {
    /// The addresses the page may be served from (`127.0.0.1:PORT`, `localhost:PORT`).
    hosts: [String; 2],
    path: PathBuf,
    max_modules: usize,
    name: String,
    mailbox: Mutex<Option<Pending>>,
    ready: Condvar,
    /// The highest sequence number a request has carried.
    latest: AtomicU64,
    /// The sequence number of the edit's run the worker is running, or 0 (a
    /// newer request stops a run; a drag is not stopped, its runner's cache
    /// must stay whole).
    running_run: AtomicU64,
    /// The flag that stops the run in progress between derivation steps.
    cancel: &'static AtomicBool,
}

enum Job {
    Run(Program),
    Drag(Box<Drag>),
}

struct Pending {
    seq: u64,
    job: Job,
    reply: mpsc::Sender<Json>,
}

#[derive(Deserialize)]
struct Envelope {
    #[serde(default)]
    seq: u64,
}

impl Studio {
    /// Binds 127.0.0.1:`port` (0: any free port) to edit the file at `path`.
    /// `max_modules` bounds every run (see [`protocol::MAX_MODULES`]).
    pub fn bind(path: &Path, port: u16, max_modules: usize) -> Result<Studio, String> {
        let server = tiny_http::Server::http(("127.0.0.1", port))
            .map_err(|e| format!("cannot listen on 127.0.0.1:{port}: {e}"))?;
        let port = server
            .server_addr()
            .to_ip()
            .map(|a| a.port())
            .ok_or_else(|| "the server has no TCP address".to_string())?;
        let state = Arc::new(State {
            hosts: [format!("127.0.0.1:{port}"), format!("localhost:{port}")],
            path: path.to_path_buf(),
            max_modules,
            name: path.display().to_string(),
            mailbox: Mutex::new(None),
            ready: Condvar::new(),
            latest: AtomicU64::new(0),
            running_run: AtomicU64::new(0),
            // One flag for the life of the process (a studio serves until it ends).
            cancel: Box::leak(Box::new(AtomicBool::new(false))),
        });
        Ok(Studio {
            server,
            state,
            port,
        })
    }

    pub fn port(&self) -> u16 {
        self.port
    }

    pub fn url(&self) -> String {
        format!("http://127.0.0.1:{}/", self.port)
    }

    /// Serves until the process ends.
    pub fn serve(self) {
        let worker = Arc::clone(&self.state);
        std::thread::spawn(move || work(&worker));
        for request in self.server.incoming_requests() {
            let state = Arc::clone(&self.state);
            std::thread::spawn(move || handle(&state, request));
        }
    }
}

/// The worker: takes the latest job, runs it, answers.
fn work(state: &State) {
    // The drag session outlives runs: a drag of the same program (text,
    // constants, seed, step) goes on from its runner's cache.
    let mut session: Option<DragSession> = None;
    loop {
        let pending = {
            let Ok(mut slot) = state.mailbox.lock() else {
                return;
            };
            loop {
                if let Some(p) = slot.take() {
                    // Under the mailbox's lock, as `submit` sets them.
                    state.cancel.store(false, Ordering::SeqCst);
                    let run = if matches!(p.job, Job::Run(_)) {
                        p.seq
                    } else {
                        0
                    };
                    state.running_run.store(run, Ordering::SeqCst);
                    break p;
                }
                slot = match state.ready.wait(slot) {
                    Ok(s) => s,
                    Err(_) => return,
                };
            }
        };
        let mut reply = match &pending.job {
            Job::Run(p) => serde_json::to_value(protocol::run(p, &state.name)).unwrap_or_default(),
            Job::Drag(d) => {
                if !session.as_ref().is_some_and(|s| s.matches(&d.program)) {
                    session = DragSession::new(&d.program).ok();
                }
                match session.as_mut().map(|s| s.drag(d, &state.name)) {
                    Some(Ok(r)) => serde_json::to_value(r).unwrap_or_default(),
                    Some(Err(e)) => json!({ "ok": false, "error": e }),
                    None => json!({ "ok": false, "error": "the program has errors" }),
                }
            }
        };
        state.running_run.store(0, Ordering::SeqCst);
        if pending.seq < state.latest.load(Ordering::SeqCst) {
            reply = superseded(pending.seq);
        }
        reply["seq"] = Json::from(pending.seq);
        let _ = pending.reply.send(reply);
    }
}

fn superseded(seq: u64) -> Json {
    json!({ "seq": seq, "superseded": true })
}

/// Puts a job in the mailbox and waits for its answer.
fn submit(state: &State, seq: u64, job: Job) -> Json {
    state.latest.fetch_max(seq, Ordering::SeqCst);
    let (tx, rx) = mpsc::channel();
    {
        let Ok(mut slot) = state.mailbox.lock() else {
            return json!({ "ok": false, "error": "the worker stopped" });
        };
        if let Some(old) = slot.take() {
            if old.seq > seq {
                // An older request arrived late: it is the one superseded.
                *slot = Some(old);
                return superseded(seq);
            }
            let _ = old.reply.send(superseded(old.seq));
        }
        // An edit's run in progress is older: stop it at its next step.
        let running = state.running_run.load(Ordering::SeqCst);
        if running != 0 && running < seq {
            state.cancel.store(true, Ordering::SeqCst);
        }
        *slot = Some(Pending {
            seq,
            job,
            reply: tx,
        });
    }
    state.ready.notify_one();
    rx.recv()
        .unwrap_or_else(|_| json!({ "ok": false, "error": "the worker stopped" }))
}

/// The file's text and version (a hash of its bytes), for loading and for
/// noticing changes made by other programs.
fn disk(path: &Path) -> Json {
    match std::fs::read(path) {
        Ok(bytes) => {
            let src = crate::source::from_bytes(path.display().to_string(), &bytes);
            json!({ "ok": true, "name": path.display().to_string(), "text": src.text, "version": version(&bytes) })
        }
        Err(e) => json!({ "ok": false, "error": format!("cannot read `{}`: {e}", path.display()) }),
    }
}

/// A stable hash of bytes (FNV-1a, 64 bits) as hex.
pub fn version(bytes: &[u8]) -> String {
    protocol::hash(bytes)
}

/// The value of a request's header.
fn header<'a>(request: &'a tiny_http::Request, name: &str) -> Option<&'a str> {
    request
        .headers()
        .iter()
        .find(|h| h.field.as_str().as_str().eq_ignore_ascii_case(name))
        .map(|h| h.value.as_str())
}

/// Why a request is refused, if it is: the studio answers only its own page.
/// A `Host` other than its own address is a DNS-rebinding attempt; an
/// `Origin` other than its own is another site's script; a POST that is not
/// JSON could come from another site's form, which a browser sends without
/// asking (JSON needs a preflight that the studio never grants).
fn refused(state: &State, request: &tiny_http::Request) -> Option<&'static str> {
    let host = header(request, "Host").unwrap_or("");
    if !state.hosts.iter().any(|h| h == host) {
        return Some("unknown host");
    }
    if let Some(origin) = header(request, "Origin")
        && !state.hosts.iter().any(|h| origin == format!("http://{h}"))
    {
        return Some("another site's request");
    }
    let json = header(request, "Content-Type").is_some_and(|t| {
        t.split(';')
            .next()
            .is_some_and(|m| m.trim() == "application/json")
    });
    if *request.method() == tiny_http::Method::Post && !json {
        return Some("not a JSON request");
    }
    None
}

fn handle(state: &State, mut request: tiny_http::Request) {
    if let Some(why) = refused(state, &request) {
        let _ = request.respond(text_response(403, why));
        return;
    }
    let url = request.url().split('?').next().unwrap_or("/").to_string();
    let method = request.method().clone();
    if method == tiny_http::Method::Get {
        let response = match url.as_str() {
            "/api/file" => json_response(&disk(&state.path)),
            _ => match assets::get(&url) {
                Some((body, kind)) => with_headers(
                    tiny_http::Response::from_data(body.to_vec()),
                    &[("Content-Type", kind), ("Cache-Control", "no-store")],
                ),
                None => text_response(404, "not found"),
            },
        };
        let _ = request.respond(response);
        return;
    }
    if method != tiny_http::Method::Post {
        let _ = request.respond(text_response(405, "method not allowed"));
        return;
    }
    let mut body = String::new();
    if request
        .as_reader()
        .take(MAX_BODY)
        .read_to_string(&mut body)
        .is_err()
    {
        let _ = request.respond(text_response(400, "the body is not UTF-8 text"));
        return;
    }
    if url == "/api/export" {
        let _ = request.respond(export(state, &body));
        return;
    }
    let reply = match api(state, &url, &body) {
        Ok(v) => v,
        Err(e) => json!({ "ok": false, "error": e }),
    };
    let _ = request.respond(json_response(&reply));
}

/// `POST /api/export`: the drawing as `lsyc run -o x.EXT` writes it (the
/// bytes, or a JSON error with status 400).
fn export(state: &State, body: &str) -> tiny_http::Response<std::io::Cursor<Vec<u8>>> {
    #[derive(Deserialize)]
    struct Export {
        #[serde(flatten)]
        program: Program,
        format: String,
    }
    let fail = |e: String| json_response(&json!({ "ok": false, "error": e })).with_status_code(400);
    let mut e: Export = match serde_json::from_str(body) {
        Ok(e) => e,
        Err(e) => return fail(format!("a request the studio does not understand: {e}")),
    };
    e.program.max_modules = Some(state.max_modules);
    let Some((_, kind)) = protocol::export_format(&e.format) else {
        return fail(format!("cannot export to .{}", e.format));
    };
    match protocol::export(&e.program, &e.format) {
        Ok(bytes) => with_headers(
            tiny_http::Response::from_data(bytes),
            &[("Content-Type", kind), ("Cache-Control", "no-store")],
        ),
        Err(e) => fail(e),
    }
}

/// Answers one POST of the API.
fn api(state: &State, url: &str, body: &str) -> Result<Json, String> {
    let bad = |e: serde_json::Error| format!("a request the studio does not understand: {e}");
    let seq = serde_json::from_str::<Envelope>(body).map_err(bad)?.seq;
    match url {
        "/api/run" => {
            let mut p: Program = serde_json::from_str(body).map_err(bad)?;
            p.max_modules = Some(state.max_modules);
            p.cancel = protocol::Cancel(Some(state.cancel));
            Ok(submit(state, seq, Job::Run(p)))
        }
        "/api/drag" => {
            let mut d: Drag = serde_json::from_str(body).map_err(bad)?;
            d.program.max_modules = Some(state.max_modules);
            Ok(submit(state, seq, Job::Drag(Box::new(d))))
        }
        "/api/const" => {
            #[derive(Deserialize)]
            struct SetConst {
                source: String,
                name: String,
                value: f64,
            }
            let c: SetConst = serde_json::from_str(body).map_err(bad)?;
            let text = protocol::set_constant(&c.source, &c.name, c.value)
                .ok_or_else(|| format!("cannot write `{}`: the program has errors", c.name))?;
            Ok(json!({ "ok": true, "source": text }))
        }
        "/api/string" => {
            let mut p: Program = serde_json::from_str(body).map_err(bad)?;
            p.max_modules = Some(state.max_modules);
            Ok(match protocol::derived_string(&p) {
                Ok((text, cut)) => json!({ "ok": true, "text": text, "cut": cut }),
                Err(diagnostics) => json!({ "ok": false, "diagnostics": diagnostics }),
            })
        }
        "/api/hover" | "/api/complete" => {
            #[derive(Deserialize)]
            struct At {
                source: String,
                /// A position in the text, in UTF-16 units (the editor's).
                at: usize,
            }
            let a: At = serde_json::from_str(body).map_err(bad)?;
            Ok(if url == "/api/hover" {
                json!({ "ok": true, "hover": protocol::hover(&a.source, a.at) })
            } else {
                json!({ "ok": true, "items": protocol::complete(&a.source, a.at) })
            })
        }
        "/api/save" => {
            #[derive(Deserialize)]
            struct Save {
                text: String,
            }
            let s: Save = serde_json::from_str(body).map_err(bad)?;
            crate::source::write_atomic(&state.path, s.text.as_bytes())
                .map_err(|e| format!("cannot write `{}`: {e}", state.name))?;
            Ok(json!({ "ok": true, "version": version(s.text.as_bytes()) }))
        }
        _ => Err(format!("no such request: {url}")),
    }
}

/// Adds headers to a response (each is an ASCII constant of this file).
fn with_headers<R: Read>(
    mut response: tiny_http::Response<R>,
    headers: &[(&str, &str)],
) -> tiny_http::Response<R> {
    for (name, value) in headers {
        if let Ok(h) = tiny_http::Header::from_bytes(name.as_bytes(), value.as_bytes()) {
            response.add_header(h);
        }
    }
    response
}

fn json_response(v: &Json) -> tiny_http::Response<std::io::Cursor<Vec<u8>>> {
    with_headers(
        tiny_http::Response::from_data(v.to_string().into_bytes()),
        &[
            ("Content-Type", "application/json"),
            ("Cache-Control", "no-store"),
        ],
    )
}

fn text_response(status: u16, text: &str) -> tiny_http::Response<std::io::Cursor<Vec<u8>>> {
    tiny_http::Response::from_data(text.as_bytes().to_vec()).with_status_code(status)
}
