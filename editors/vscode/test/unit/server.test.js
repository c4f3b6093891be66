// server.js: the `exsce.server.command` setting made into a program that exists.
"use strict";

const assert = require("node:assert/strict");
const fs = require("node:fs");
const os = require("node:os");
const path = require("node:path");
const { after, test } = require("node:test");
const { resolveServer, expandVariables, ServerNotFound } = require("../../server");

const made = [];

function folder() {
  const created = fs.mkdtempSync(path.join(os.tmpdir(), "exsce-server-"));
  made.push(created);
  return created;
}

after(() => {
  for (const each of made) fs.rmSync(each, { recursive: true, force: true });
});

function program(file, mode = 0o755) {
  fs.mkdirSync(path.dirname(file), { recursive: true });
  fs.writeFileSync(file, "#!/bin/sh\n");
  fs.chmodSync(file, mode);
  return file;
}

test("a bare name is looked up on PATH, in order", () => {
  const first = folder();
  const second = folder();
  program(path.join(second, "exscec"));
  const found = program(path.join(first, "exscec"));
  const env = { PATH: [first, second].join(path.delimiter) };
  assert.deepEqual(resolveServer({ env }), { command: found, args: ["lsp"], source: "PATH" });
});

test("a file that is not executable is passed over", () => {
  const dir = folder();
  program(path.join(dir, "exscec"), 0o644);
  assert.throws(() => resolveServer({ env: { PATH: dir } }), ServerNotFound);
});

test("an absolute path is used as it is, with the arguments given", () => {
  const exscec = program(path.join(folder(), "bin", "exscec"));
  const server = resolveServer({ command: exscec, args: ["lsp", "--debug"], env: { PATH: "" } });
  assert.deepEqual(server, { command: exscec, args: ["lsp", "--debug"], source: "exsce.server.command" });
});

test("a relative path is taken from the first workspace folder", () => {
  const workspace = folder();
  const exscec = program(path.join(workspace, "tools", "exscec"));
  const server = resolveServer({ command: "tools/exscec", workspaceFolders: [workspace], env: { PATH: "" } });
  assert.equal(server.command, exscec);
});

test("${workspaceFolder}, ${userHome}, ${env:NAME} and ~ are expanded", () => {
  const options = { workspaceFolders: ["/work/spec"], env: { VENV: "/opt/venv" }, home: "/home/ada" };
  assert.equal(expandVariables("${workspaceFolder}/.venv/bin/exscec", options), "/work/spec/.venv/bin/exscec");
  assert.equal(expandVariables("${userHome}/bin/exscec", options), "/home/ada/bin/exscec");
  assert.equal(expandVariables("${env:VENV}/bin/exscec", options), "/opt/venv/bin/exscec");
  assert.equal(expandVariables("~/bin/exscec", options), path.join("/home/ada", "bin/exscec"));
  assert.equal(expandVariables("exscec", options), "exscec");
});

test("the workspace's .venv is tried when PATH has no exscec, in a trusted workspace only", () => {
  const workspace = folder();
  const exscec = program(path.join(workspace, ".venv", "bin", "exscec"));
  const options = { workspaceFolders: [workspace], env: { PATH: folder() }, platform: "linux" };
  assert.deepEqual(resolveServer({ ...options, trusted: true }), {
    command: exscec,
    args: ["lsp"],
    source: "the workspace's virtual environment",
  });
  assert.throws(() => resolveServer({ ...options, trusted: false }), ServerNotFound);
});

test("not found: the message says what was tried and which setting to change", () => {
  const workspace = folder();
  let error;
  try {
    resolveServer({ workspaceFolders: [workspace], trusted: true, env: { PATH: folder() }, platform: "linux" });
  } catch (caught) {
    error = caught;
  }
  assert.ok(error instanceof ServerNotFound);
  assert.match(error.message, /'exscec' was not found/);
  assert.match(error.message, /'exscec' on PATH/);
  assert.ok(error.message.includes(path.join(workspace, ".venv", "bin", "exscec")));
  assert.match(error.message, /"exsce\.server\.command"/);
});

test("on Windows a name is found with an extension of PATHEXT, and .venv\\Scripts is tried", () => {
  const dir = folder();
  const exe = program(path.join(dir, "exscec.exe"), 0o644); // no executable bit on Windows
  const env = { PATH: dir, PATHEXT: ".COM;.EXE;.BAT" };
  assert.equal(resolveServer({ env, platform: "win32" }).command, exe);

  const workspace = folder();
  const venvExe = program(path.join(workspace, ".venv", "Scripts", "exscec.exe"), 0o644);
  const options = { workspaceFolders: [workspace], trusted: true, env: { PATH: folder(), PATHEXT: ".EXE" } };
  assert.equal(resolveServer({ ...options, platform: "win32" }).command, venvExe);
});
