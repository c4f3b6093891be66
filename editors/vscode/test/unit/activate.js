#!/usr/bin/env node
// Activate and deactivate extension.js once, in this process, under the fake
// `vscode` of vscode-stub.js; print what happened as JSON on the last line.
//
//   node test/unit/activate.js '{"server.command": "...", "server.args": ["lsp"]}'
//
// EXSCE_EXTENSION names another extension.js to load, such as the one unpacked
// from a .vsix (with the node_modules bundled beside it).
//
// A process of its own per run: extension.js and vscode-languageclient keep module
// state, and a server that dies while starting leaves promises of
// vscode-languageclient 9 unhandled (VS Code only logs them; they are counted here).
"use strict";

const path = require("path");
const { installFakeVscode } = require("./vscode-stub");

const seen = installFakeVscode(JSON.parse(process.argv[2] || "{}"));
const rejections = [];
process.on("unhandledRejection", (error) => rejections.push(String(error && error.message)));

(async () => {
  const extension = require(process.env.EXSCE_EXTENSION || path.resolve(__dirname, "..", "..", "extension.js"));
  await extension.activate({ subscriptions: [] });
  const client = extension.languageClient();
  const running = Boolean(client && client.isRunning());
  const capabilities = running ? client.initializeResult.capabilities : null;
  await extension.deactivate();
  await new Promise((resolve) => setTimeout(resolve, 100)); // let late rejections arrive
  const result = {
    running,
    capabilities,
    stopped: extension.languageClient() === undefined,
    errors: seen.errors,
    output: seen.output,
    rejections,
  };
  process.stdout.write("\n" + JSON.stringify(result) + "\n");
  process.exit(0); // a server process that ignored `exit` must not keep us here
})();
