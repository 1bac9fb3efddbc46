//! The server's main loop: one thread, one message at a time.
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
use std::collections::HashMap;
use std::io::{self, BufRead, Write};
use std::panic::{AssertUnwindSafe, catch_unwind};

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
}

/// How the session ended: `exit` after `shutdown` is a clean end (the
/// process exits 0); `exit` without it, or the input closing, is not (1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    Clean,
    Abrupt,
}

/// Serves one client over `input` and `output` until `exit` or the end of
/// the input.
pub fn serve(mut input: impl BufRead, output: impl Write) -> io::Result<End> {
    let mut s = Server {
        out: output,
        state: State::Uninitialized,
        docs: HashMap::new(),
    };
    loop {
        match transport::read(&mut input)? {
            Incoming::Eof => return Ok(End::Abrupt),
            Incoming::Invalid { id, code, message } => {
                transport::write_error(&mut s.out, id, code, &message)?;
            }
            Incoming::Message(Message::Request(r)) => {
                let resp = s.request(r);
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
                Ok(format::format(&a.text))
            }),
            req::RangeFormatting::METHOD => self.on::<req::RangeFormatting>(r, |s, p| {
                let a = s.doc(&p.text_document.uri)?;
                let range = a.lines.span(&a.text, p.range);
                Ok(format::format_range(&a.text, range))
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
        let result = catch_unwind(AssertUnwindSafe(|| f(self, params))).unwrap_or_else(|_| {
            Err(error(
                ErrorCode::InternalError,
                format!("lsyc failed while answering `{}`", R::METHOD),
            ))
        });
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
