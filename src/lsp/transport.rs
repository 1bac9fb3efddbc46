//! JSON-RPC over a byte stream with `Content-Length` framing.
//!
//! Owns: reading one framed message and telling a well-formed message from a
//! broken one, and writing messages. lsp-server's own stdio transport ends the
//! connection at the first malformed message; this one answers it with a
//! protocol error (JSON-RPC's parse error or invalid request) and reads on, so
//! that a client's mistake never takes the server down.

use lsp_server::{ErrorCode, Message};
use serde_json::Value;
use std::io::{self, BufRead, Read, Write};

/// The largest message body read: the largest source file lsyc reads, escaped
/// in JSON, fits.
pub const MAX_BODY: usize = 160 * 1024 * 1024;
/// The longest header line read.
const MAX_HEADER_LINE: u64 = 8 * 1024;

/// What one read gave.
#[derive(Debug)]
pub enum Incoming {
    Message(Message),
    /// A message that cannot be understood: the server answers it with a
    /// protocol error for `id` (JSON `null` when the id is unknown).
    Invalid {
        id: Value,
        code: ErrorCode,
        message: String,
    },
    /// The stream ended.
    Eof,
}

fn invalid(id: Value, code: ErrorCode, message: impl Into<String>) -> Incoming {
    Incoming::Invalid {
        id,
        code,
        message: message.into(),
    }
}

/// Reads one message: headers up to an empty line, then `Content-Length`
/// bytes of JSON.
pub fn read(r: &mut impl BufRead) -> io::Result<Incoming> {
    let mut length: Option<Result<usize, String>> = None;
    let mut saw_header = false;
    let mut line = Vec::new();
    loop {
        line.clear();
        let n = r
            .by_ref()
            .take(MAX_HEADER_LINE)
            .read_until(b'\n', &mut line)?;
        if n == 0 {
            return Ok(if saw_header {
                invalid(
                    Value::Null,
                    ErrorCode::ParseError,
                    "the stream ended inside a message's headers",
                )
            } else {
                Incoming::Eof
            });
        }
        if !line.ends_with(b"\n") {
            // A header line longer than any real one: skip the rest of it.
            skip_line(r)?;
            length = Some(Err("a header line is too long".into()));
            saw_header = true;
            continue;
        }
        let text = String::from_utf8_lossy(&line);
        let text = text.trim_end_matches(['\r', '\n']);
        if text.is_empty() {
            if saw_header {
                break;
            }
            continue; // blank lines between messages
        }
        saw_header = true;
        match text.split_once(':') {
            Some((name, value)) if name.trim().eq_ignore_ascii_case("content-length") => {
                length =
                    Some(value.trim().parse::<usize>().map_err(|_| {
                        format!("`Content-Length: {}` is not a length", value.trim())
                    }));
            }
            Some(_) => {} // Content-Type and others
            None => length = Some(Err(format!("`{text}` is not a header"))),
        }
    }
    let len = match length {
        None => {
            return Ok(invalid(
                Value::Null,
                ErrorCode::ParseError,
                "a message without `Content-Length`",
            ));
        }
        Some(Err(e)) => return Ok(invalid(Value::Null, ErrorCode::ParseError, e)),
        Some(Ok(n)) => n,
    };
    if len > MAX_BODY {
        io::copy(&mut r.by_ref().take(len as u64), &mut io::sink())?;
        return Ok(invalid(
            Value::Null,
            ErrorCode::ParseError,
            format!("a message of {len} bytes; the server reads at most {MAX_BODY}"),
        ));
    }
    let mut body = vec![0; len];
    if let Err(e) = r.read_exact(&mut body) {
        return if e.kind() == io::ErrorKind::UnexpectedEof {
            Ok(invalid(
                Value::Null,
                ErrorCode::ParseError,
                "the stream ended inside a message",
            ))
        } else {
            Err(e)
        };
    }
    Ok(parse(&body))
}

fn skip_line(r: &mut impl BufRead) -> io::Result<()> {
    loop {
        let buf = r.fill_buf()?;
        if buf.is_empty() {
            return Ok(());
        }
        match buf.iter().position(|&b| b == b'\n') {
            Some(i) => {
                r.consume(i + 1);
                return Ok(());
            }
            None => {
                let n = buf.len();
                r.consume(n);
            }
        }
    }
}

/// A message body: JSON that is not JSON is a parse error; JSON that is not a
/// request, response or notification is an invalid request.
pub fn parse(body: &[u8]) -> Incoming {
    let value: Value = match serde_json::from_slice(body) {
        Ok(v) => v,
        Err(e) => {
            return invalid(
                Value::Null,
                ErrorCode::ParseError,
                format!("the message is not JSON: {e}"),
            );
        }
    };
    let id = match value.get("id") {
        Some(id @ (Value::Number(_) | Value::String(_))) => id.clone(),
        _ => Value::Null,
    };
    if !value.is_object() {
        return invalid(
            id,
            ErrorCode::InvalidRequest,
            "a message must be a JSON object",
        );
    }
    let has_id = value.get("id").is_some_and(|v| !v.is_null());
    match serde_json::from_value::<Message>(value) {
        // A message with an id the server cannot echo is not a notification.
        Ok(Message::Notification(_)) if has_id => invalid(
            id,
            ErrorCode::InvalidRequest,
            "a request id must be an integer or a string",
        ),
        Ok(m) => Incoming::Message(m),
        Err(e) => invalid(
            id,
            ErrorCode::InvalidRequest,
            format!("not a JSON-RPC message: {e}"),
        ),
    }
}

/// Writes one message with its `Content-Length` header.
pub fn write(w: &mut impl Write, msg: Message) -> io::Result<()> {
    msg.write(w)
}

/// Writes an error response whose id may be `null` (which `lsp_server`'s
/// `RequestId` cannot hold).
pub fn write_error(
    w: &mut impl Write,
    id: Value,
    code: ErrorCode,
    message: &str,
) -> io::Result<()> {
    let v = serde_json::json!({
        "jsonrpc": "2.0",
        "id": id,
        "error": { "code": code as i32, "message": message },
    });
    let text = v.to_string();
    write!(w, "Content-Length: {}\r\n\r\n{text}", text.len())?;
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(body: &str) -> String {
        format!("Content-Length: {}\r\n\r\n{body}", body.len())
    }

    fn read_all(input: &str) -> Vec<String> {
        let mut r = io::BufReader::new(input.as_bytes());
        let mut out = Vec::new();
        loop {
            match read(&mut r).expect("in memory") {
                Incoming::Eof => return out,
                Incoming::Message(m) => out.push(format!(
                    "message {}",
                    serde_json::to_string(&m).expect("json")
                )),
                Incoming::Invalid { id, code, .. } => {
                    out.push(format!("invalid {id} {}", code as i32))
                }
            }
        }
    }

    #[test]
    fn broken_messages_do_not_stop_reading() {
        let input = [
            frame(r#"{"jsonrpc":"2.0","id":1,"method":"a"}"#),
            frame("{not json"),
            frame("[1, 2]"),
            frame(r#"{"jsonrpc":"2.0","id":1.5,"method":"b"}"#),
            "Content-Length: many\r\n\r\n".to_string(),
            "Bogus\r\n\r\n".to_string(),
            frame(r#"{"jsonrpc":"2.0","method":"c"}"#),
            "Content-Length: 40\r\n\r\n{}".to_string(),
        ]
        .concat();
        let got = read_all(&input);
        assert_eq!(
            got,
            [
                r#"message {"id":1,"method":"a"}"#,
                "invalid null -32700",
                "invalid null -32600",
                "invalid 1.5 -32600",
                "invalid null -32700",
                "invalid null -32700",
                r#"message {"method":"c"}"#,
                "invalid null -32700",
            ]
        );
    }
}
