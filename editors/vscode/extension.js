// The exsce extension: starts the exsce language server (`exscec lsp`, LSP over
// stdio) for .exsce files and folds them by braces.  Highlighting, snippets and
// the language configuration are declared in package.json and need no code.
"use strict";

const vscode = require("vscode");
const { LanguageClient, TransportKind, CloseAction, ErrorAction } = require("vscode-languageclient/node");
const { resolveServer, ServerNotFound } = require("./server");
const { foldingRanges } = require("./folding");

const CLIENT_ID = "exsce"; // the client reads its trace level from `exsce.trace.server`
const CLIENT_NAME = "exsce Language Server";
const SELECTOR = [
  { scheme: "file", language: "exsce" },
  { scheme: "untitled", language: "exsce" },
];
const MAX_RESTARTS = 4; // crashes within RESTART_WINDOW_MS before giving up
const RESTART_WINDOW_MS = 3 * 60 * 1000;

/** @type {LanguageClient | undefined} */
let client;
/** @type {vscode.OutputChannel} */
let output;

function activate(context) {
  output = vscode.window.createOutputChannel(CLIENT_NAME);
  context.subscriptions.push(output);

  context.subscriptions.push(
    vscode.languages.registerFoldingRangeProvider(SELECTOR, { provideFoldingRanges: provideFolding })
  );
  context.subscriptions.push(
    vscode.commands.registerCommand("exsce.restartServer", () => restart()),
    vscode.workspace.onDidChangeConfiguration((event) => {
      if (event.affectsConfiguration("exsce.server")) restart();
    }),
    vscode.workspace.onDidGrantWorkspaceTrust(() => {
      if (!client) restart();
    }),
    { dispose: () => stop() }
  );
  return start();
}

function deactivate() {
  return stop();
}

function provideFolding(document) {
  const kinds = { comment: vscode.FoldingRangeKind.Comment, region: vscode.FoldingRangeKind.Region };
  return foldingRanges(document.getText()).map(
    (range) => new vscode.FoldingRange(range.start, range.end, kinds[range.kind])
  );
}

async function start() {
  const settings = vscode.workspace.getConfiguration("exsce");
  let server;
  try {
    server = resolveServer({
      command: settings.get("server.command", "exscec"),
      args: settings.get("server.args", ["lsp"]),
      workspaceFolders: (vscode.workspace.workspaceFolders || []).map((folder) => folder.uri.fsPath),
      trusted: vscode.workspace.isTrusted,
    });
  } catch (error) {
    if (!(error instanceof ServerNotFound)) throw error;
    output.appendLine(error.message);
    showError(`${error.message} Highlighting and snippets work without it.`);
    return;
  }
  const commandLine = [server.command, ...server.args].join(" ");
  output.appendLine(`Starting ${commandLine} (found on ${server.source})`);

  const executable = { command: server.command, args: server.args, transport: TransportKind.stdio };
  const started = { yes: false };
  try {
    client = new LanguageClient(
      CLIENT_ID,
      CLIENT_NAME,
      { run: executable, debug: executable },
      {
        documentSelector: SELECTOR,
        outputChannel: output,
        // Imports: a change to another .exsce file can change this one's diagnostics.
        synchronize: { fileEvents: vscode.workspace.createFileSystemWatcher("**/*.exsce") },
        errorHandler: restartPolicy(commandLine, started),
        initializationFailedHandler: () => false, // reported below, once
      }
    );
    await client.start();
    // A server that exits while starting leaves start() resolved but the client stopped.
    if (!client.isRunning()) throw new Error("it stopped while starting");
    started.yes = true;
  } catch (error) {
    const failed = client;
    client = undefined;
    if (failed) failed.dispose().catch(() => undefined); // it is not running: nothing to stop
    const message = error && error.message ? error.message : String(error);
    output.appendLine(`The language server did not start: ${message}`);
    showError(
      `exsce: the language server '${commandLine}' did not start: ${message}. ` +
        `Its messages are in the '${CLIENT_NAME}' output. Is your exscec recent enough to have the 'lsp' command?`
    );
  }
}

/**
 * Restart after a crash, unless it keeps crashing; then say where to look.  A server that
 * stops before it has started is not restarted: start() reports it.
 */
function restartPolicy(commandLine, started) {
  const crashes = [];
  return {
    // A broken message now and then is survivable; a stream of them is not (as the default).
    error: (_error, _message, count) => ({
      action: count !== undefined && count <= 3 ? ErrorAction.Continue : ErrorAction.Shutdown,
    }),
    closed: () => {
      if (!started.yes) return { action: CloseAction.DoNotRestart, handled: true };
      const now = Date.now();
      crashes.push(now);
      while (crashes.length && now - crashes[0] > RESTART_WINDOW_MS) crashes.shift();
      if (crashes.length <= MAX_RESTARTS) return { action: CloseAction.Restart };
      return {
        action: CloseAction.DoNotRestart,
        message:
          `exsce: the language server '${commandLine}' stopped ` +
          `${crashes.length} times in a few minutes and will not be restarted. ` +
          `Its messages are in the '${CLIENT_NAME}' output; run 'exsce: Restart Language Server' once fixed.`,
      };
    },
  };
}

async function stop() {
  const running = client;
  client = undefined;
  if (running) {
    try {
      await running.stop();
    } catch (error) {
      output.appendLine(`Stopping the language server: ${error && error.message ? error.message : error}`);
    }
  }
}

/** Stop, then start again; restarts asked for in a row run one after the other. */
let restarting = Promise.resolve();
function restart() {
  restarting = restarting
    .then(stop)
    .then(start)
    .catch((error) => output.appendLine(`Restarting the language server: ${error && error.message ? error.message : error}`));
  return restarting;
}

function showError(message) {
  vscode.window.showErrorMessage(message, "Open Settings", "Show Output").then((choice) => {
    if (choice === "Open Settings") {
      vscode.commands.executeCommand("workbench.action.openSettings", "exsce.server");
    } else if (choice === "Show Output") {
      output.show(true);
    }
  });
}

/** The running client, if any (for tests). */
function languageClient() {
  return client;
}

module.exports = { activate, deactivate, languageClient };
