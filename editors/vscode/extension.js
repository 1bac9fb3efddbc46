// The client: starts `lsyc lsp` on stdio for .lsy files. Everything the editor
// shows (diagnostics, hover, definitions, completion, symbols, rename,
// formatting) comes from the server; this file only starts it.
"use strict";

const vscode = require("vscode");
const { LanguageClient, TransportKind } = require("vscode-languageclient/node");

let client;

function activate(context) {
  const command = vscode.workspace.getConfiguration("lsy").get("server.path", "lsyc");
  const run = { command, args: ["lsp"], transport: TransportKind.stdio };
  client = new LanguageClient(
    "lsy",
    "lsyc language server",
    { run, debug: run },
    { documentSelector: [{ language: "lsy" }] }
  );
  context.subscriptions.push({ dispose: () => client && client.stop() });
  return client.start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
