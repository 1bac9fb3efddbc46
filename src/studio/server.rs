//! The studio's HTTP server (hyper on tokio, on 127.0.0.1 only): the page's
//! assets from the binary, and a JSON API that the page calls with `fetch`.
//!
//! Routes: `GET /` and the assets; `GET /api/file` (the file's text and
//! version); `POST /api/run` and `POST /api/drag` (through the worker pool);
//! `POST /api/const` (a constant's value written into the source);
//! `POST /api/string` (the derived string of a step); `POST /api/save` (the
//! file written atomically, unless it changed on disk since the page loaded
//! it); `POST /api/hover` and `POST /api/complete` (the language server's
//! answers at a place in the text); `POST /api/export` (the drawing as SVG,
//! PNG, OBJ or GLB).
//!
//! Resources are bounded: at most [`MAX_CONNECTIONS`] connections (a new one
//! closes the connection idle the longest, so idle sockets never lock the
//! page out), idle and slow clients closed after [`IDLE_TIMEOUT`], request
//! bodies of at most [`MAX_BODY`] bytes and [`BODY_BUDGET`] bytes of them in
//! memory at once, programs run by a small pool of workers (`jobs`).
//!
//! Owns: sockets, connections, the file on disk. Must not run programs
//! itself: `protocol` does, on `jobs`' workers.

use super::assets;
use super::jobs::{MAX_SESSION_ID, Pool, Session, Sessions};
use super::protocol::{self, Drag, Program};
use http_body_util::{BodyExt, Full, Limited};
use hyper::body::{Bytes, Incoming};
use hyper::header::{CONTENT_LENGTH, HeaderValue};
use hyper::{Method, Request, Response, StatusCode};
use hyper_util::rt::{TokioIo, TokioTimer};
use serde::Deserialize;
use serde_json::{Value as Json, json};
use std::collections::BTreeMap;
use std::convert::Infallible;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};
use tokio::sync::{Notify, Semaphore};

/// The largest request body read: a program the studio runs is at most
/// [`crate::lsp::analysis::MAX_DOCUMENT_BYTES`], and JSON may escape it.
pub const MAX_BODY: usize = 16 << 20;

/// The bytes of request bodies held at once (a request waits for its share).
pub const BODY_BUDGET: usize = 64 << 20;

/// The most connections open at once. A browser opens at most six to one
/// server; beyond the limit, a new connection closes the one idle longest.
pub const MAX_CONNECTIONS: usize = 128;

/// A connection with no request in progress for this long is closed: an
/// idle keep-alive connection, or a client that has not finished sending
/// its request's headers.
pub const IDLE_TIMEOUT: Duration = Duration::from_secs(20);

/// The time a client has to send a request's headers (hyper's own timer).
pub const HEADER_TIMEOUT: Duration = Duration::from_secs(10);

/// The time a client has to send a request's body.
pub const BODY_TIMEOUT: Duration = Duration::from_secs(30);

/// The studio's server, bound and ready.
pub struct Studio {
    listener: std::net::TcpListener,
    state: Arc<State>,
    port: u16,
}

struct State {
    /// The addresses the page may be served from (`127.0.0.1:PORT`, `localhost:PORT`).
    hosts: [String; 2],
    path: PathBuf,
    max_modules: usize,
    name: String,
    pool: Pool,
    /// Hover and completion: one at a time, on their own worker.
    words: Pool,
    sessions: Sessions,
    /// The bytes of request bodies in memory, in MiB.
    budget: Semaphore,
    /// The last analysis made for hover and completion, by the text's hash:
    /// concurrent questions about one text share it.
    analysis: tokio::sync::Mutex<Option<(String, Arc<crate::lsp::analysis::Analysis>)>>,
    /// Saves one at a time (the check of the file's version and the write).
    saving: tokio::sync::Mutex<()>,
    conns: Mutex<Conns>,
    started: Instant,
}

/// The open connections, oldest first.
#[derive(Default)]
struct Conns {
    next: u64,
    open: BTreeMap<u64, Arc<Conn>>,
}

/// What the server knows of one connection.
struct Conn {
    /// Requests in progress on it.
    busy: AtomicUsize,
    /// When it last finished a request (ms since the server started).
    last: AtomicU64,
    /// Closes it.
    close: Notify,
}

impl Conn {
    fn idle_ms(&self, now: u64) -> Option<u64> {
        (self.busy.load(Ordering::SeqCst) == 0)
            .then(|| now.saturating_sub(self.last.load(Ordering::SeqCst)))
    }
}

/// What every request of the page carries: its session and sequence number.
#[derive(Deserialize)]
struct Envelope {
    #[serde(default)]
    seq: u64,
    #[serde(default)]
    session: String,
}

type Reply = Response<Full<Bytes>>;

impl Studio {
    /// Binds 127.0.0.1:`port` (0: any free port) to edit the file at `path`.
    /// `max_modules` bounds every run (see [`protocol::MAX_MODULES`]).
    pub fn bind(path: &Path, port: u16, max_modules: usize) -> Result<Studio, String> {
        let listener = std::net::TcpListener::bind(("127.0.0.1", port))
            .map_err(|e| format!("cannot listen on 127.0.0.1:{port}: {e}"))?;
        let port = listener
            .local_addr()
            .map_err(|e| format!("the server has no address: {e}"))?
            .port();
        listener
            .set_nonblocking(true)
            .map_err(|e| format!("cannot listen on 127.0.0.1:{port}: {e}"))?;
        let state = Arc::new(State {
            hosts: [format!("127.0.0.1:{port}"), format!("localhost:{port}")],
            path: path.to_path_buf(),
            max_modules,
            name: path.display().to_string(),
            pool: Pool::for_machine(),
            words: Pool::new(1),
            sessions: Sessions::default(),
            budget: Semaphore::new(BODY_BUDGET >> 20),
            analysis: tokio::sync::Mutex::new(None),
            saving: tokio::sync::Mutex::new(()),
            conns: Mutex::new(Conns::default()),
            started: Instant::now(),
        });
        Ok(Studio {
            listener,
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

    /// Serves until the process ends; an error only if the server cannot start.
    pub fn serve(self) -> Result<(), String> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .enable_all()
            .build()
            .map_err(|e| format!("cannot start the server: {e}"))?;
        runtime.block_on(async move {
            let listener = tokio::net::TcpListener::from_std(self.listener)
                .map_err(|e| format!("cannot listen on 127.0.0.1:{}: {e}", self.port))?;
            accept(listener, self.state).await;
            Ok(())
        })
    }
}

/// Accepts connections for ever. An error (out of file descriptors, say)
/// waits a moment and goes on: the server never ends on its own.
async fn accept(listener: tokio::net::TcpListener, state: Arc<State>) {
    loop {
        match listener.accept().await {
            Ok((stream, _)) => {
                let Some((id, conn)) = admit(&state) else {
                    drop(stream); // every connection is busy: refused
                    continue;
                };
                tokio::spawn(connection(Arc::clone(&state), stream, id, conn));
            }
            Err(_) => tokio::time::sleep(Duration::from_millis(50)).await,
        }
    }
}

impl State {
    fn now_ms(&self) -> u64 {
        u64::try_from(self.started.elapsed().as_millis()).unwrap_or(u64::MAX)
    }
}

/// Registers a new connection, closing the one idle longest when there are
/// [`MAX_CONNECTIONS`]; `None` if all of them are busy.
fn admit(state: &State) -> Option<(u64, Arc<Conn>)> {
    let now = state.now_ms();
    let mut conns = state.conns.lock().unwrap_or_else(PoisonError::into_inner);
    if conns.open.len() >= MAX_CONNECTIONS {
        let idlest = conns
            .open
            .iter()
            .filter_map(|(id, c)| c.idle_ms(now).map(|ms| (ms, *id)))
            .max()?;
        if let Some(c) = conns.open.remove(&idlest.1) {
            c.close.notify_one();
        }
    }
    let id = conns.next;
    conns.next += 1;
    let conn = Arc::new(Conn {
        busy: AtomicUsize::new(0),
        last: AtomicU64::new(now),
        close: Notify::new(),
    });
    conns.open.insert(id, Arc::clone(&conn));
    Some((id, conn))
}

/// Serves one connection until the client closes it, it stays idle too
/// long, or a newer connection needs its place.
async fn connection(state: Arc<State>, stream: tokio::net::TcpStream, id: u64, conn: Arc<Conn>) {
    let service = {
        let state = Arc::clone(&state);
        let conn = Arc::clone(&conn);
        hyper::service::service_fn(move |request| {
            let state = Arc::clone(&state);
            let conn = Arc::clone(&conn);
            async move {
                conn.busy.fetch_add(1, Ordering::SeqCst);
                let reply = handle(&state, request).await;
                conn.last.store(state.now_ms(), Ordering::SeqCst);
                conn.busy.fetch_sub(1, Ordering::SeqCst);
                Ok::<_, Infallible>(reply)
            }
        })
    };
    let served = hyper::server::conn::http1::Builder::new()
        .timer(TokioTimer::new())
        .header_read_timeout(HEADER_TIMEOUT)
        .serve_connection(TokioIo::new(stream), service);
    tokio::select! {
        _ = served => {}
        () = conn.close.notified() => {}
        () = idle(&state, &conn) => {}
    }
    state
        .conns
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .open
        .remove(&id);
}

/// Finishes when the connection has had no request in progress for
/// [`IDLE_TIMEOUT`].
async fn idle(state: &State, conn: &Conn) {
    let limit = u64::try_from(IDLE_TIMEOUT.as_millis()).unwrap_or(u64::MAX);
    loop {
        tokio::time::sleep(Duration::from_secs(1)).await;
        if conn.idle_ms(state.now_ms()).is_some_and(|ms| ms >= limit) {
            return;
        }
    }
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

/// The value of a request's header, if it is text.
fn header<'a>(request: &'a Request<Incoming>, name: &str) -> Option<&'a str> {
    request.headers().get(name).and_then(|v| v.to_str().ok())
}

/// Why a request is refused, if it is: the studio answers only its own page.
/// A `Host` other than its own address is a DNS-rebinding attempt; an
/// `Origin` other than its own is another site's script; a POST that is not
/// JSON could come from another site's form, which a browser sends without
/// asking (JSON needs a preflight that the studio never grants).
fn refused(state: &State, request: &Request<Incoming>) -> Option<&'static str> {
    let host = header(request, "host").unwrap_or("");
    if !state.hosts.iter().any(|h| h == host) {
        return Some("unknown host");
    }
    if let Some(origin) = header(request, "origin")
        && !state.hosts.iter().any(|h| origin == format!("http://{h}"))
    {
        return Some("another site's request");
    }
    let json = header(request, "content-type").is_some_and(|t| {
        t.split(';')
            .next()
            .is_some_and(|m| m.trim() == "application/json")
    });
    if request.method() == Method::POST && !json {
        return Some("not a JSON request");
    }
    None
}

async fn handle(state: &Arc<State>, request: Request<Incoming>) -> Reply {
    if let Some(why) = refused(state, &request) {
        return text_response(StatusCode::FORBIDDEN, why);
    }
    let url = request.uri().path().to_string();
    if request.method() == Method::GET {
        return get(state, &url).await;
    }
    if request.method() != Method::POST {
        return text_response(StatusCode::METHOD_NOT_ALLOWED, "method not allowed");
    }
    let length = request
        .headers()
        .get(CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.parse::<usize>().ok());
    let Some(length) = length else {
        return text_response(StatusCode::LENGTH_REQUIRED, "a POST needs a Content-Length");
    };
    if length > MAX_BODY {
        let why = format!("the request is over {} MiB", MAX_BODY >> 20);
        return json_error(StatusCode::PAYLOAD_TOO_LARGE, &why);
    }
    // Its share of the bodies held at once, in MiB, rounded up.
    let share = u32::try_from(length.div_ceil(1 << 20).max(1)).unwrap_or(u32::MAX);
    let Ok(_share) = state.budget.acquire_many(share).await else {
        return text_response(StatusCode::SERVICE_UNAVAILABLE, "the server is stopping");
    };
    let body = match read_body(request.into_body()).await {
        Ok(b) => b,
        Err(why) => return text_response(StatusCode::BAD_REQUEST, &why),
    };
    if url == "/api/export" {
        return export(state, &body).await;
    }
    let reply = match api(state, &url, body).await {
        Ok(v) => v,
        Err(e) => json!({ "ok": false, "error": e }),
    };
    json_response(&reply)
}

async fn get(state: &Arc<State>, url: &str) -> Reply {
    if url == "/api/file" {
        let path = state.path.clone();
        let file = tokio::task::spawn_blocking(move || disk(&path)).await;
        return json_response(
            &file.unwrap_or_else(|e| json!({ "ok": false, "error": e.to_string() })),
        );
    }
    match assets::get(url) {
        Some((body, kind)) => with_type(Response::new(Full::new(Bytes::from_static(body))), kind),
        None => text_response(StatusCode::NOT_FOUND, "not found"),
    }
}

/// A request's body as text: at most [`MAX_BODY`] bytes, within [`BODY_TIMEOUT`].
async fn read_body(body: Incoming) -> Result<String, String> {
    let collected = tokio::time::timeout(BODY_TIMEOUT, Limited::new(body, MAX_BODY).collect())
        .await
        .map_err(|_| "the request's body came too slowly".to_string())?
        .map_err(|e| format!("cannot read the request: {e}"))?;
    String::from_utf8(collected.to_bytes().to_vec())
        .map_err(|_| "the body is not UTF-8 text".to_string())
}

fn bad(e: serde_json::Error) -> String {
    format!("a request the studio does not understand: {e}")
}

/// The session a request names (the page makes up one id per load).
fn session_of(state: &State, body: &str) -> Result<(Arc<Session>, u64), String> {
    let e: Envelope = serde_json::from_str(body).map_err(bad)?;
    if e.session.len() > MAX_SESSION_ID {
        return Err(format!("a session id is at most {MAX_SESSION_ID} bytes"));
    }
    Ok((state.sessions.get(&e.session), e.seq))
}

fn superseded(seq: u64) -> Json {
    json!({ "seq": seq, "superseded": true })
}

/// Answers one POST of the API.
async fn api(state: &Arc<State>, url: &str, body: String) -> Result<Json, String> {
    match url {
        "/api/run" => {
            let mut p: Program = serde_json::from_str(&body).map_err(bad)?;
            p.max_modules = Some(state.max_modules);
            run(state, &body, p).await
        }
        "/api/drag" => {
            let mut d: Drag = serde_json::from_str(&body).map_err(bad)?;
            d.program.max_modules = Some(state.max_modules);
            drag(state, &body, d).await
        }
        "/api/const" => set_constant(state, &body).await,
        "/api/string" => {
            let mut p: Program = serde_json::from_str(&body).map_err(bad)?;
            p.max_modules = Some(state.max_modules);
            string(state, &body, p).await
        }
        "/api/hover" | "/api/complete" => words(state, url, &body).await,
        "/api/save" => save(state, &body).await,
        _ => Err(format!("no such request: {url}")),
    }
}

/// `POST /api/run`: the newest edit of its session wins; an older run in
/// progress is stopped.
async fn run(state: &Arc<State>, body: &str, mut p: Program) -> Result<Json, String> {
    let (session, seq) = session_of(state, body)?;
    if !session.begin_edit(seq) {
        return Ok(superseded(seq));
    }
    let name = state.name.clone();
    let out = state
        .pool
        .run(session.edit_after(seq), move |flag| {
            p.cancel = protocol::Cancel(Some(flag));
            serde_json::to_value(protocol::run(&p, &name)).unwrap_or_default()
        })
        .await;
    Ok(answer(&session, seq, out))
}

/// The reply to edit `seq`, or `superseded` if a newer edit came meanwhile.
fn answer(session: &Session, seq: u64, out: Option<Json>) -> Json {
    match out {
        Some(mut reply) if !session.edited_since(seq) => {
            reply["seq"] = Json::from(seq);
            reply
        }
        _ => superseded(seq),
    }
}

/// `POST /api/drag`: as a run; the session keeps the drag's runner between
/// moves (and forgets it when a move is stopped, its cache being partial).
async fn drag(state: &Arc<State>, body: &str, mut d: Drag) -> Result<Json, String> {
    let (session, seq) = session_of(state, body)?;
    if !session.begin_edit(seq) {
        return Ok(superseded(seq));
    }
    let name = state.name.clone();
    let held = Arc::clone(&session);
    let out = state
        .pool
        .run(session.edit_after(seq), move |flag| {
            d.program.cancel = protocol::Cancel(Some(flag));
            let mut slot = held.drag.lock().unwrap_or_else(PoisonError::into_inner);
            if !slot.as_ref().is_some_and(|s| s.matches(&d.program)) {
                *slot = protocol::DragSession::new(&d.program).ok();
            }
            let reply = match slot.as_mut().map(|s| s.drag(&d, &name)) {
                Some(Ok(r)) => serde_json::to_value(r).unwrap_or_default(),
                Some(Err(e)) => json!({ "ok": false, "error": e }),
                None => json!({ "ok": false, "error": "the program has errors" }),
            };
            if flag.load(Ordering::SeqCst) {
                *slot = None;
            }
            reply
        })
        .await;
    Ok(answer(&session, seq, out))
}

/// `POST /api/string`: stopped by a newer string request or a newer edit.
async fn string(state: &Arc<State>, body: &str, mut p: Program) -> Result<Json, String> {
    let (session, _) = session_of(state, body)?;
    let n = session.begin_string();
    let edits = session.last_edit();
    let newer_string = session.string_after(n);
    let newer_edit = session.edit_after(edits);
    let stopped = async move {
        tokio::select! {
            () = newer_string => {}
            () = newer_edit => {}
        }
    };
    let out = state
        .pool
        .run(stopped, move |flag| {
            p.cancel = protocol::Cancel(Some(flag));
            match protocol::derived_string(&p) {
                Ok((text, cut)) => json!({ "ok": true, "text": text, "cut": cut }),
                Err(diagnostics) => json!({ "ok": false, "diagnostics": diagnostics }),
            }
        })
        .await;
    Ok(out.unwrap_or_else(|| superseded(0)))
}

/// `POST /api/const`: a constant's value written into the source.
async fn set_constant(state: &Arc<State>, body: &str) -> Result<Json, String> {
    #[derive(Deserialize)]
    struct SetConst {
        source: String,
        name: String,
        value: f64,
    }
    let c: SetConst = serde_json::from_str(body).map_err(bad)?;
    let name = c.name.clone();
    let text = state
        .pool
        .run_to_end(move |_| protocol::set_constant(&c.source, &c.name, c.value))
        .await
        .flatten()
        .ok_or_else(|| format!("cannot write `{name}`: the program has errors"))?;
    Ok(json!({ "ok": true, "source": text }))
}

/// `POST /api/hover` and `/api/complete`: the language server's answers,
/// from one analysis of the text shared by every question about it.
async fn words(state: &Arc<State>, url: &str, body: &str) -> Result<Json, String> {
    #[derive(Deserialize)]
    struct At {
        source: String,
        /// A position in the text, in UTF-16 units (the editor's).
        at: usize,
    }
    let a: At = serde_json::from_str(body).map_err(bad)?;
    let key = protocol::hash(a.source.as_bytes());
    let analysis = {
        let mut cached = state.analysis.lock().await;
        match cached.as_ref().filter(|(k, _)| *k == key) {
            Some((_, an)) => Arc::clone(an),
            None => {
                let source = a.source.clone();
                let made = state
                    .words
                    .run_to_end(move |_| Arc::new(crate::lsp::analysis::Analysis::new(source)))
                    .await
                    .ok_or("the analysis failed")?;
                *cached = Some((key, Arc::clone(&made)));
                made
            }
        }
    };
    let hover = url == "/api/hover";
    let out = state
        .words
        .run_to_end(move |_| {
            if hover {
                json!({ "ok": true, "hover": protocol::hover_in(&analysis, a.at) })
            } else {
                json!({ "ok": true, "items": protocol::complete_in(&analysis, a.at) })
            }
        })
        .await;
    out.ok_or_else(|| "the answer failed".to_string())
}

/// `POST /api/save`: writes the file, unless it changed on disk since the
/// version the page loaded (`base`): then nothing is written and the reply
/// says so, with the file as it is now.
async fn save(state: &Arc<State>, body: &str) -> Result<Json, String> {
    #[derive(Deserialize)]
    struct Save {
        text: String,
        /// The version of the file the page's text started from.
        #[serde(default)]
        base: Option<String>,
    }
    let s: Save = serde_json::from_str(body).map_err(bad)?;
    let _one = state.saving.lock().await;
    let path = state.path.clone();
    let name = state.name.clone();
    tokio::task::spawn_blocking(move || save_file(&path, &name, &s.text, s.base.as_deref()))
        .await
        .map_err(|e| format!("cannot write `{}`: {e}", state.name))?
}

fn save_file(path: &Path, name: &str, text: &str, base: Option<&str>) -> Result<Json, String> {
    if let Some(base) = base {
        let now = std::fs::read(path).map_or_else(|_| version(b""), |b| version(&b));
        if now != base {
            return Ok(json!({
                "ok": false,
                "conflict": true,
                "error": format!("not saved: `{name}` changed on disk since it was loaded"),
                "disk": disk(path),
            }));
        }
    }
    crate::source::write_atomic(path, text.as_bytes())
        .map_err(|e| format!("cannot write `{name}`: {e}"))?;
    Ok(json!({ "ok": true, "version": version(text.as_bytes()) }))
}

/// `POST /api/export`: the drawing as `lsyc run -o x.EXT` writes it (the
/// bytes, or a JSON error with status 400). A newer edit of the page stops it.
async fn export(state: &Arc<State>, body: &str) -> Reply {
    #[derive(Deserialize)]
    struct Export {
        #[serde(flatten)]
        program: Program,
        format: String,
    }
    let fail = |e: &str| json_error(StatusCode::BAD_REQUEST, e);
    let mut e: Export = match serde_json::from_str(body) {
        Ok(e) => e,
        Err(e) => return fail(&bad(e)),
    };
    let (session, _) = match session_of(state, body) {
        Ok(s) => s,
        Err(e) => return fail(&e),
    };
    e.program.max_modules = Some(state.max_modules);
    let Some((_, kind)) = protocol::export_format(&e.format) else {
        return fail(&format!("cannot export to .{}", e.format));
    };
    let edits = session.last_edit();
    let out = state
        .pool
        .run(session.edit_after(edits), move |flag| {
            e.program.cancel = protocol::Cancel(Some(flag));
            protocol::export(&e.program, &e.format)
        })
        .await;
    match out {
        Some(Ok(bytes)) => with_type(Response::new(Full::new(Bytes::from(bytes))), kind),
        Some(Err(e)) => fail(&e),
        None => json_error(
            StatusCode::CONFLICT,
            "the export was stopped: the program was edited meanwhile",
        ),
    }
}

/// A response with a content type, never cached.
fn with_type(mut r: Reply, kind: &'static str) -> Reply {
    let h = r.headers_mut();
    h.insert("content-type", HeaderValue::from_static(kind));
    h.insert("cache-control", HeaderValue::from_static("no-store"));
    r
}

fn json_response(v: &Json) -> Reply {
    let r = Response::new(Full::new(Bytes::from(v.to_string())));
    with_type(r, "application/json")
}

fn json_error(status: StatusCode, e: &str) -> Reply {
    let mut r = json_response(&json!({ "ok": false, "error": e }));
    *r.status_mut() = status;
    r
}

fn text_response(status: StatusCode, text: &str) -> Reply {
    let mut r = Response::new(Full::new(Bytes::from(text.to_string())));
    *r.status_mut() = status;
    with_type(r, "text/plain; charset=utf-8")
}
