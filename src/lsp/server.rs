//! The server's main loop: one thread, one message at a time (`lsyc lsp`
//! reads its input on a second thread, a few messages ahead, so that a
//! `$/cancelRequest` stops a request still waiting, and marks the request
//! being answered cancelled the moment its `$/cancelRequest` arrives).
//!
//! Owns: the protocol's life cycle (initialize, shutdown, exit), the open
//! documents, and dispatching requests by type to the features. Every request
//! gets an answer: a result, or a JSON-RPC error (not initialized, unknown
//! method, invalid params, shut down, or an internal error if a feature
//! panicked). Analysis is fast enough (see docs/lsp.md) to run on every change
//! in the loop itself, so there is no queue, no debouncing and no stale state.

use super::analysis::Analysis;
use super::transport::{self, Incoming};
use super::{actions, complete, format, hover, outline, rename, semantic, signature, text};
use lsp_server::{ErrorCode, Message, Notification, Request, Response, ResponseError};
use lsp_types as lsp;
use lsp_types::notification::{self as note, Notification as _};
use lsp_types::request::{self as req, Request as _};
use std::collections::{HashMap, HashSet, VecDeque};
use std::io::{self, BufRead, Write};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    Uninitialized,
    Running,
    ShutDown,
}

struct Document {
    version: i32,
    analysis: Analysis,
}

pub struct Server<W: Write> {
    out: W,
    state: State,
    docs: HashMap<String, Document>,
    running: Arc<Running>,
}

/// The request being answered, shared with the thread that reads the
/// input: a `$/cancelRequest` naming it raises `cancelled` at once, while
/// the loop is still busy with it. The loop looks at the flag when the
/// request's parameters are read and when its answer is ready (before the
/// answer is serialized and sent); a cancelled request is answered
/// `RequestCanceled` and its result dropped.
#[derive(Default)]
struct Running {
    id: Mutex<Option<lsp_server::RequestId>>,
    cancelled: AtomicBool,
}

impl Running {
    fn start(&self, id: &lsp_server::RequestId) {
        let mut running = self.id.lock().unwrap_or_else(|e| e.into_inner());
        self.cancelled.store(false, Ordering::SeqCst);
        *running = Some(id.clone());
    }

    fn finish(&self) {
        *self.id.lock().unwrap_or_else(|e| e.into_inner()) = None;
    }

    /// Marks the request cancelled if it is the one being answered.
    fn cancel(&self, id: &lsp_server::RequestId) {
        let running = self.id.lock().unwrap_or_else(|e| e.into_inner());
        if running.as_ref() == Some(id) {
            self.cancelled.store(true, Ordering::SeqCst);
        }
    }

    fn is_cancelled(&self) -> bool {
        self.cancelled.load(Ordering::SeqCst)
    }
}

/// How the session ended: `exit` after `shutdown` is a clean end (the
/// process exits 0); `exit` without it, or the input closing, is not (1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    Clean,
    Abrupt,
}

/// Where messages come from: `next` waits for one; `ready` gives one only if
/// it has already arrived (so that the loop can see a `$/cancelRequest` for
/// a request it has not answered yet).
trait Source {
    fn next(&mut self) -> io::Result<Incoming>;
    fn ready(&mut self) -> Option<io::Result<Incoming>>;
}

/// Messages read on the loop's own thread: nothing is ever ready early.
struct Direct<R>(R);

impl<R: BufRead> Source for Direct<R> {
    fn next(&mut self) -> io::Result<Incoming> {
        transport::read(&mut self.0)
    }

    fn ready(&mut self) -> Option<io::Result<Incoming>> {
        None
    }
}

/// Messages read by a thread of their own, a few ahead of the loop.
struct Reader(std::sync::mpsc::Receiver<io::Result<Incoming>>);

impl Source for Reader {
    fn next(&mut self) -> io::Result<Incoming> {
        self.0.recv().unwrap_or(Ok(Incoming::Eof))
    }

    fn ready(&mut self) -> Option<io::Result<Incoming>> {
        self.0.try_recv().ok()
    }
}

/// The most messages read ahead of the one being answered (a client that
/// sends more waits: memory stays bounded however many it sends).
const READ_AHEAD: usize = 64;

/// Serves one client over `input` and `output` until `exit` or the end of
/// the input, reading on the calling thread (a `$/cancelRequest` is seen
/// only once the requests before it are answered).
pub fn serve(input: impl BufRead, output: impl Write) -> io::Result<End> {
    run(&mut Direct(input), output, Arc::default())
}

/// As [`serve`], with the input read by a thread of its own, so that a
/// `$/cancelRequest` that arrives while earlier requests are answered stops
/// its request before it starts, and one that arrives while its request is
/// answered drops the answer (either way answered `RequestCanceled`).
pub fn serve_threaded(input: impl BufRead + Send + 'static, output: impl Write) -> io::Result<End> {
    let (tx, rx) = std::sync::mpsc::sync_channel(READ_AHEAD);
    let running = Arc::new(Running::default());
    let seen = Arc::clone(&running);
    std::thread::spawn(move || {
        let mut input = input;
        loop {
            let m = transport::read(&mut input);
            let end = matches!(m, Ok(Incoming::Eof) | Err(_));
            if let Ok(m) = &m
                && let Some(id) = cancelled_id(m)
            {
                seen.cancel(&id);
            }
            if tx.send(m).is_err() || end {
                return;
            }
        }
    });
    run(&mut Reader(rx), output, running)
}

/// The id a `$/cancelRequest` names, if `m` is one.
fn cancelled_id(m: &Incoming) -> Option<lsp_server::RequestId> {
    let Incoming::Message(Message::Notification(n)) = m else {
        return None;
    };
    if n.method != note::Cancel::METHOD {
        return None;
    }
    let p: lsp::CancelParams = serde_json::from_value(n.params.clone()).ok()?;
    Some(match p.id {
        lsp::NumberOrString::Number(i) => i.into(),
        lsp::NumberOrString::String(s) => s.into(),
    })
}

/// The messages read but not yet handled, and the requests among them that
/// the client cancelled.
#[derive(Default)]
struct Queue {
    waiting: VecDeque<Incoming>,
    cancelled: HashSet<lsp_server::RequestId>,
}

impl Queue {
    /// Reads what has already arrived (up to [`READ_AHEAD`] messages),
    /// noting cancellations of the requests waiting and of `current`, the
    /// one about to be answered.
    fn look_ahead(
        &mut self,
        source: &mut dyn Source,
        current: &lsp_server::RequestId,
    ) -> io::Result<()> {
        while self.waiting.len() < READ_AHEAD {
            let Some(m) = source.ready() else {
                return Ok(());
            };
            let m = m?;
            if let Some(id) = cancelled_id(&m) {
                let waiting = self
                    .waiting
                    .iter()
                    .any(|w| matches!(w, Incoming::Message(Message::Request(r)) if r.id == id));
                if waiting || id == *current {
                    self.cancelled.insert(id);
                }
            }
            self.waiting.push_back(m);
        }
        Ok(())
    }
}

fn run(source: &mut dyn Source, output: impl Write, running: Arc<Running>) -> io::Result<End> {
    let mut s = Server {
        out: output,
        state: State::Uninitialized,
        docs: HashMap::new(),
        running,
    };
    let mut queue = Queue::default();
    loop {
        let m = match queue.waiting.pop_front() {
            Some(m) => m,
            None => source.next()?,
        };
        match m {
            Incoming::Eof => return Ok(End::Abrupt),
            Incoming::Invalid { id, code, message } => {
                transport::write_error(&mut s.out, id, code, &message)?;
            }
            Incoming::Message(Message::Request(r)) => {
                // Running from here: a cancellation the reader sees from now
                // on raises the flag; one read before is in the queue, and
                // `look_ahead` finds it.
                s.running.start(&r.id);
                queue.look_ahead(source, &r.id)?;
                let resp = if queue.cancelled.remove(&r.id) || s.running.is_cancelled() {
                    cancelled(r.id, &r.method)
                } else {
                    s.request(r)
                };
                s.running.finish();
                transport::write(&mut s.out, resp.into())?;
            }
            Incoming::Message(Message::Notification(n)) => {
                if n.method == note::Exit::METHOD {
                    return Ok(if s.state == State::ShutDown {
                        End::Clean
                    } else {
                        End::Abrupt
                    });
                }
                s.notification(n)?;
            }
            // The server sends no requests, so no response is awaited.
            Incoming::Message(Message::Response(_)) => {}
        }
    }
}

fn cancelled(id: lsp_server::RequestId, method: &str) -> Response {
    Response {
        id,
        response_result: Err(error(
            ErrorCode::RequestCanceled,
            format!("`{method}` was cancelled"),
        )),
    }
}

fn error(code: ErrorCode, message: impl Into<String>) -> ResponseError {
    ResponseError {
        code: code as i32,
        message: message.into(),
        data: None,
    }
}

/// The capabilities this server offers.
pub fn capabilities() -> lsp::ServerCapabilities {
    lsp::ServerCapabilities {
        position_encoding: Some(lsp::PositionEncodingKind::UTF16),
        text_document_sync: Some(lsp::TextDocumentSyncCapability::Options(
            lsp::TextDocumentSyncOptions {
                open_close: Some(true),
                change: Some(lsp::TextDocumentSyncKind::INCREMENTAL),
                ..Default::default()
            },
        )),
        hover_provider: Some(lsp::HoverProviderCapability::Simple(true)),
        definition_provider: Some(lsp::OneOf::Left(true)),
        references_provider: Some(lsp::OneOf::Left(true)),
        document_highlight_provider: Some(lsp::OneOf::Left(true)),
        completion_provider: Some(lsp::CompletionOptions {
            trigger_characters: Some(vec!["?".to_string()]),
            ..Default::default()
        }),
        signature_help_provider: Some(lsp::SignatureHelpOptions {
            trigger_characters: Some(vec!["(".to_string(), ",".to_string()]),
            retrigger_characters: None,
            work_done_progress_options: Default::default(),
        }),
        semantic_tokens_provider: Some(
            lsp::SemanticTokensServerCapabilities::SemanticTokensOptions(
                lsp::SemanticTokensOptions {
                    legend: semantic::legend(),
                    full: Some(lsp::SemanticTokensFullOptions::Bool(true)),
                    range: None,
                    work_done_progress_options: Default::default(),
                },
            ),
        ),
        document_symbol_provider: Some(lsp::OneOf::Left(true)),
        document_formatting_provider: Some(lsp::OneOf::Left(true)),
        document_range_formatting_provider: Some(lsp::OneOf::Left(true)),
        code_action_provider: Some(lsp::CodeActionProviderCapability::Options(
            lsp::CodeActionOptions {
                code_action_kinds: Some(vec![lsp::CodeActionKind::QUICKFIX]),
                ..Default::default()
            },
        )),
        rename_provider: Some(lsp::OneOf::Right(lsp::RenameOptions {
            prepare_provider: Some(true),
            work_done_progress_options: Default::default(),
        })),
        ..Default::default()
    }
}

impl<W: Write> Server<W> {
    fn request(&mut self, r: Request) -> Response {
        let id = r.id.clone();
        match (self.state, r.method.as_str()) {
            (State::Uninitialized, req::Initialize::METHOD) => {
                self.state = State::Running;
                let result = lsp::InitializeResult {
                    capabilities: capabilities(),
                    server_info: Some(lsp::ServerInfo {
                        name: "lsyc".to_string(),
                        version: Some(env!("CARGO_PKG_VERSION").to_string()),
                    }),
                };
                Response::new_ok(id, result)
            }
            (State::Uninitialized, m) => Response {
                id,
                response_result: Err(error(
                    ErrorCode::ServerNotInitialized,
                    format!("`{m}` before `initialize`"),
                )),
            },
            (State::ShutDown, m) => Response {
                id,
                response_result: Err(error(
                    ErrorCode::InvalidRequest,
                    format!("`{m}` after `shutdown`; only `exit` is left"),
                )),
            },
            (State::Running, req::Initialize::METHOD) => Response {
                id,
                response_result: Err(error(
                    ErrorCode::InvalidRequest,
                    "the server is already initialized",
                )),
            },
            (State::Running, req::Shutdown::METHOD) => {
                self.state = State::ShutDown;
                Response::new_ok(id, ())
            }
            (State::Running, _) => self.dispatch(r),
        }
    }

    // lsp-types keys `WorkspaceEdit::changes` by `Uri`, which clippy deems
    // mutable (a cache inside); the map is built and sent, never mutated by key.
    #[allow(clippy::mutable_key_type)]
    fn dispatch(&mut self, r: Request) -> Response {
        let m = r.method.clone();
        match m.as_str() {
            req::HoverRequest::METHOD => self.on::<req::HoverRequest>(r, |s, p| {
                let (a, off) = s.at(&p.text_document_position_params)?;
                Ok(hover::hover(a, off))
            }),
            req::GotoDefinition::METHOD => self.on::<req::GotoDefinition>(r, |s, p| {
                let tdp = &p.text_document_position_params;
                let (a, off) = s.at(tdp)?;
                let Some(sym) = a.index.at(off).and_then(|o| a.index.symbol(&o.target)) else {
                    return Ok(None);
                };
                let locs: Vec<lsp::Location> = sym
                    .definition()
                    .into_iter()
                    .map(|sp| lsp::Location {
                        uri: tdp.text_document.uri.clone(),
                        range: a.range(sp),
                    })
                    .collect();
                Ok(match locs.len() {
                    0 => None,
                    1 => locs
                        .into_iter()
                        .next()
                        .map(lsp::GotoDefinitionResponse::Scalar),
                    _ => Some(lsp::GotoDefinitionResponse::Array(locs)),
                })
            }),
            req::References::METHOD => self.on::<req::References>(r, |s, p| {
                let tdp = &p.text_document_position;
                let (a, off) = s.at(tdp)?;
                let Some(o) = a.index.at(off) else {
                    return Ok(None);
                };
                Ok(Some(
                    a.index
                        .occurrences_of(&o.target)
                        .filter(|x| p.context.include_declaration || !x.decl)
                        .map(|x| lsp::Location {
                            uri: tdp.text_document.uri.clone(),
                            range: a.range(x.span),
                        })
                        .collect(),
                ))
            }),
            req::DocumentHighlightRequest::METHOD => {
                self.on::<req::DocumentHighlightRequest>(r, |s, p| {
                    let (a, off) = s.at(&p.text_document_position_params)?;
                    let Some(o) = a.index.at(off) else {
                        return Ok(None);
                    };
                    Ok(Some(
                        a.index
                            .occurrences_of(&o.target)
                            .map(|x| lsp::DocumentHighlight {
                                range: a.range(x.span),
                                kind: Some(if x.decl {
                                    lsp::DocumentHighlightKind::WRITE
                                } else {
                                    lsp::DocumentHighlightKind::READ
                                }),
                            })
                            .collect(),
                    ))
                })
            }
            req::Completion::METHOD => self.on::<req::Completion>(r, |s, p| {
                let (a, off) = s.at(&p.text_document_position)?;
                Ok(Some(lsp::CompletionResponse::Array(complete::complete(
                    a, off,
                ))))
            }),
            req::SignatureHelpRequest::METHOD => self.on::<req::SignatureHelpRequest>(r, |s, p| {
                let (a, off) = s.at(&p.text_document_position_params)?;
                Ok(signature::signature_help(a, off))
            }),
            req::SemanticTokensFullRequest::METHOD => {
                self.on::<req::SemanticTokensFullRequest>(r, |s, p| {
                    let a = s.doc(&p.text_document.uri)?;
                    Ok(Some(lsp::SemanticTokensResult::Tokens(semantic::tokens(a))))
                })
            }
            req::DocumentSymbolRequest::METHOD => {
                self.on::<req::DocumentSymbolRequest>(r, |s, p| {
                    let a = s.doc(&p.text_document.uri)?;
                    Ok(Some(lsp::DocumentSymbolResponse::Nested(outline::outline(
                        a,
                    ))))
                })
            }
            req::Formatting::METHOD => self.on::<req::Formatting>(r, |s, p| {
                let a = s.doc(&p.text_document.uri)?;
                Ok(format::format(a))
            }),
            req::RangeFormatting::METHOD => self.on::<req::RangeFormatting>(r, |s, p| {
                let a = s.doc(&p.text_document.uri)?;
                let range = a.lines.span(&a.text, p.range);
                Ok(format::format_range(a, range))
            }),
            req::CodeActionRequest::METHOD => self.on::<req::CodeActionRequest>(r, |s, p| {
                let a = s.doc(&p.text_document.uri)?;
                // `only` keeps the actions of these kinds and their sub-kinds.
                let wanted = |k: &lsp::CodeActionKind| matches!(k.as_str(), "" | "quickfix");
                if p.context
                    .only
                    .as_ref()
                    .is_some_and(|o| !o.iter().any(wanted))
                {
                    return Ok(None);
                }
                let fixes = actions::quick_fixes(a, &p.text_document.uri, p.range);
                Ok(Some(
                    fixes
                        .into_iter()
                        .map(lsp::CodeActionOrCommand::CodeAction)
                        .collect(),
                ))
            }),
            req::PrepareRenameRequest::METHOD => self.on::<req::PrepareRenameRequest>(r, |s, p| {
                let (a, off) = s.at(&p)?;
                let (span, name) =
                    rename::prepare(a, off).map_err(|m| error(ErrorCode::RequestFailed, m))?;
                Ok(Some(lsp::PrepareRenameResponse::RangeWithPlaceholder {
                    range: a.range(span),
                    placeholder: name,
                }))
            }),
            req::Rename::METHOD => self.on::<req::Rename>(r, |s, p| {
                let tdp = &p.text_document_position;
                let (a, off) = s.at(tdp)?;
                let edits = rename::rename(a, off, &p.new_name)
                    .map_err(|m| error(ErrorCode::RequestFailed, m))?;
                let mut changes = HashMap::new();
                changes.insert(tdp.text_document.uri.clone(), edits);
                Ok(Some(lsp::WorkspaceEdit {
                    changes: Some(changes),
                    ..Default::default()
                }))
            }),
            other => Response {
                id: r.id,
                response_result: Err(error(
                    ErrorCode::MethodNotFound,
                    format!("lsyc does not handle `{other}`"),
                )),
            },
        }
    }

    /// Runs one request of type `R`: its parameters read by type, a panic in
    /// the feature turned into an internal error.
    fn on<R: req::Request>(
        &mut self,
        r: Request,
        f: impl FnOnce(&Self, R::Params) -> Result<R::Result, ResponseError>,
    ) -> Response {
        let params: R::Params = match serde_json::from_value(r.params) {
            Ok(p) => p,
            Err(e) => {
                return Response {
                    id: r.id,
                    response_result: Err(error(
                        ErrorCode::InvalidParams,
                        format!("invalid parameters for `{}`: {e}", R::METHOD),
                    )),
                };
            }
        };
        if self.running.is_cancelled() {
            return cancelled(r.id, R::METHOD);
        }
        let result = catch_unwind(AssertUnwindSafe(|| f(self, params))).unwrap_or_else(|_| {
            Err(error(
                ErrorCode::InternalError,
                format!("lsyc failed while answering `{}`", R::METHOD),
            ))
        });
        // Cancelled while it ran: the answer is dropped, not serialized.
        if self.running.is_cancelled() {
            return cancelled(r.id, R::METHOD);
        }
        match result.and_then(|v| {
            serde_json::to_value(v).map_err(|e| error(ErrorCode::InternalError, e.to_string()))
        }) {
            Ok(v) => Response {
                id: r.id,
                response_result: Ok(v),
            },
            Err(e) => Response {
                id: r.id,
                response_result: Err(e),
            },
        }
    }

    fn doc(&self, uri: &lsp::Uri) -> Result<&Analysis, ResponseError> {
        self.docs
            .get(uri.as_str())
            .map(|d| &d.analysis)
            .ok_or_else(|| {
                error(
                    ErrorCode::InvalidParams,
                    format!("`{}` is not open", uri.as_str()),
                )
            })
    }

    fn at(&self, p: &lsp::TextDocumentPositionParams) -> Result<(&Analysis, usize), ResponseError> {
        let a = self.doc(&p.text_document.uri)?;
        Ok((a, a.offset(p.position)))
    }

    fn notification(&mut self, n: Notification) -> io::Result<()> {
        if self.state != State::Running {
            return Ok(()); // dropped, as the protocol says, before `initialize`
        }
        match n.method.as_str() {
            note::DidOpenTextDocument::METHOD => {
                if let Ok(p) = serde_json::from_value::<lsp::DidOpenTextDocumentParams>(n.params) {
                    let d = p.text_document;
                    self.update(d.uri, d.version, d.text)?;
                }
            }
            note::DidChangeTextDocument::METHOD => {
                if let Ok(p) = serde_json::from_value::<lsp::DidChangeTextDocumentParams>(n.params)
                {
                    let uri = p.text_document.uri;
                    if let Some(doc) = self.docs.get(uri.as_str()) {
                        let mut text = doc.analysis.text.clone();
                        text::apply_changes(&mut text, p.content_changes);
                        self.update(uri, p.text_document.version, text)?;
                    }
                }
            }
            note::DidCloseTextDocument::METHOD => {
                if let Ok(p) = serde_json::from_value::<lsp::DidCloseTextDocumentParams>(n.params) {
                    let uri = p.text_document.uri;
                    self.docs.remove(uri.as_str());
                    self.publish(uri, Vec::new(), None)?;
                }
            }
            _ => {} // initialized, didSave, $/cancelRequest, $/setTrace, …
        }
        Ok(())
    }

    /// Analyses a document's new text and publishes its diagnostics.
    fn update(&mut self, uri: lsp::Uri, version: i32, text: String) -> io::Result<()> {
        let Ok(analysis) = catch_unwind(AssertUnwindSafe(|| Analysis::new(text))) else {
            return Ok(()); // the last analysis stays; the panic is on stderr
        };
        let diags = analysis.lsp_diagnostics(&uri);
        self.docs
            .insert(uri.as_str().to_string(), Document { version, analysis });
        self.publish(uri, diags, Some(version))
    }

    fn publish(
        &mut self,
        uri: lsp::Uri,
        diagnostics: Vec<lsp::Diagnostic>,
        version: Option<i32>,
    ) -> io::Result<()> {
        let params = lsp::PublishDiagnosticsParams {
            uri,
            diagnostics,
            version,
        };
        let n = Notification::new(note::PublishDiagnostics::METHOD.to_string(), params);
        transport::write(&mut self.out, n.into())
    }

    /// The version of an open document (for tests and tools).
    pub fn version(&self, uri: &str) -> Option<i32> {
        self.docs.get(uri).map(|d| d.version)
    }
}
