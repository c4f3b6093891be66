#!/usr/bin/env node
// A language server that only shakes hands: it answers `initialize` and `shutdown`,
// and writes each method it receives to the file named by FAKE_SERVER_LOG.  With
// FAKE_SERVER_EXIT=N it exits with status N at once, as an exscec without `lsp` does.
"use strict";

const fs = require("fs");

if (process.env.FAKE_SERVER_EXIT) {
  process.stderr.write("Error: No such command 'lsp'.\n");
  process.exit(Number(process.env.FAKE_SERVER_EXIT));
}

const log = (method) => fs.appendFileSync(process.env.FAKE_SERVER_LOG, method + "\n");
const send = (message) => {
  const body = JSON.stringify({ jsonrpc: "2.0", ...message });
  process.stdout.write(`Content-Length: ${Buffer.byteLength(body)}\r\n\r\n${body}`);
};

let buffer = Buffer.alloc(0);
process.stdin.on("data", (data) => {
  buffer = Buffer.concat([buffer, data]);
  for (;;) {
    const headerEnd = buffer.indexOf("\r\n\r\n");
    if (headerEnd < 0) return;
    const length = Number(/Content-Length: (\d+)/i.exec(buffer.subarray(0, headerEnd).toString())[1]);
    if (buffer.length < headerEnd + 4 + length) return;
    const message = JSON.parse(buffer.subarray(headerEnd + 4, headerEnd + 4 + length).toString());
    buffer = buffer.subarray(headerEnd + 4 + length);
    log(message.method);
    if (message.method === "initialize") {
      send({ id: message.id, result: { capabilities: { textDocumentSync: 1, hoverProvider: true } } });
    } else if (message.method === "shutdown") {
      send({ id: message.id, result: null });
    } else if (message.method === "exit") {
      process.exit(0);
    }
  }
});
