// extension.js with vscode-languageclient, outside VS Code (a fake `vscode`, see
// activate.js): it finds the server, shakes hands with it over stdio, stops it, and
// says clearly when it cannot.  With EXSCE_SERVER_COMMAND set
// (tests/test_vscode_extension.py sets it to the real exscec when it has `lsp`), it
// also starts `exscec lsp` and checks what the server offers.
"use strict";

const assert = require("node:assert/strict");
const { execFileSync } = require("node:child_process");
const fs = require("node:fs");
const os = require("node:os");
const path = require("node:path");
const { after, test } = require("node:test");

const ACTIVATE = path.join(__dirname, "activate.js");
const FAKE_SERVER = path.join(__dirname, "fake-server.js");

const made = [];

after(() => {
  for (const each of made) fs.rmSync(each, { recursive: true, force: true });
});

/** Activate and deactivate in a process of its own; what it saw, and the methods the fake server got. */
function activate(settings, env = {}) {
  const scratch = fs.mkdtempSync(path.join(os.tmpdir(), "exsce-lsp-"));
  made.push(scratch);
  const log = path.join(scratch, "methods.log");
  const stdout = execFileSync(process.execPath, [ACTIVATE, JSON.stringify(settings)], {
    env: { ...process.env, FAKE_SERVER_LOG: log, ...env },
    encoding: "utf8",
    timeout: 60000,
  });
  const result = JSON.parse(stdout.trim().split("\n").pop());
  result.methods = fs.existsSync(log) ? fs.readFileSync(log, "utf8").trim().split("\n") : [];
  return result;
}

test("a missing command is reported once, naming the setting", () => {
  const seen = activate({ "server.command": "exscec-that-is-not-installed" });
  assert.equal(seen.running, false);
  assert.equal(seen.errors.length, 1, seen.errors.join("\n"));
  assert.match(seen.errors[0], /'exscec-that-is-not-installed' was not found/);
  assert.match(seen.errors[0], /"exsce\.server\.command"/);
  assert.match(seen.errors[0], /Highlighting and snippets work without it/);
});

test("the server is started over stdio, initialized, and shut down", () => {
  const seen = activate({ "server.command": FAKE_SERVER, "server.args": ["lsp"] });
  assert.equal(seen.running, true, seen.output.join("\n"));
  assert.equal(seen.capabilities.hoverProvider, true);
  assert.deepEqual(seen.errors, []);
  assert.ok(seen.output.includes(`Starting ${FAKE_SERVER} lsp (found on exsce.server.command)`), seen.output.join("\n"));
  assert.equal(seen.stopped, true);
  assert.deepEqual(seen.methods, ["initialize", "initialized", "shutdown", "exit"]);
  assert.deepEqual(seen.rejections, []);
});

test("a server that exits at once is reported once, and not restarted", () => {
  const seen = activate({ "server.command": FAKE_SERVER, "server.args": ["lsp"] }, { FAKE_SERVER_EXIT: "2" });
  assert.equal(seen.running, false);
  const ours = seen.errors.filter((message) => message.startsWith("exsce:"));
  assert.equal(ours.length, 1, seen.errors.join("\n"));
  assert.match(ours[0], /did not start: it stopped while starting/);
  assert.match(ours[0], /'lsp' command/);
  assert.ok(seen.output.some((line) => line.includes("No such command 'lsp'")), "the server's stderr is shown");
  assert.equal(seen.output.filter((line) => line.startsWith("Starting ")).length, 1, "started once");
});

// What the language server of issue 9 offers; the editor side relies on each.
const CAPABILITIES = [
  "textDocumentSync",
  "completionProvider",
  "hoverProvider",
  "definitionProvider",
  "referencesProvider",
  "renameProvider",
  "documentFormattingProvider",
  "codeActionProvider",
  "documentSymbolProvider",
];

test("the real exscec lsp starts and offers every feature", { skip: !process.env.EXSCE_SERVER_COMMAND }, () => {
  const seen = activate({ "server.command": process.env.EXSCE_SERVER_COMMAND, "server.args": ["lsp"] });
  assert.equal(seen.running, true, [...seen.errors, ...seen.output].join("\n"));
  const missing = CAPABILITIES.filter((name) => !seen.capabilities[name]);
  assert.deepEqual(missing, [], `exscec lsp does not offer ${missing.join(", ")}`);
  assert.equal(seen.stopped, true);
});
