// Just enough of the `vscode` module for extension.js and vscode-languageclient to
// start and stop a server outside VS Code.  What a test looks at is explicit
// (settings in, error messages and output lines out); anything else is a
// stand-in that accepts every call.
"use strict";

const Module = require("module");

function standIn(name) {
  return new Proxy(function () {}, {
    get: (_target, key) => {
      if (key === "then") return undefined; // not a promise
      if (key === Symbol.iterator) return function* () {};
      if (key === Symbol.toPrimitive) return () => name;
      return standIn(`${name}.${String(key)}`);
    },
    apply: () => standIn(`${name}()`),
    construct: () => standIn(`new ${name}`),
  });
}

/** A fake `vscode`, with `settings` to change and `seen` to look at between tests. */
function fakeVscode() {
  const state = { settings: {}, folders: [], trusted: true, errors: [], output: [] };
  const workspace = {
    getConfiguration: () => ({ get: (key, fallback) => (key in state.settings ? state.settings[key] : fallback) }),
    get workspaceFolders() {
      return state.folders.map((fsPath) => ({ uri: { fsPath } }));
    },
    get isTrusted() {
      return state.trusted;
    },
    textDocuments: [],
  };
  const window = {
    showErrorMessage: (message) => {
      state.errors.push(message);
      return Promise.resolve(undefined);
    },
    createOutputChannel: () => ({
      append: (text) => state.output.push(text),
      appendLine: (line) => state.output.push(line),
      replace() {},
      clear() {},
      show() {},
      hide() {},
      dispose() {},
    }),
  };
  const env = { appName: "Visual Studio Code", language: "en", machineId: "test", sessionId: "test" };
  const known = { version: "1.90.0", env, workspace, window };
  const vscode = new Proxy(
    {},
    {
      get: (_target, key) => {
        if (!(key in known)) return standIn(`vscode.${String(key)}`);
        const value = known[key];
        if (typeof value !== "object") return value;
        return new Proxy(value, { get: (obj, k) => (k in obj ? obj[k] : standIn(`vscode.${key}.${String(k)}`)) });
      },
    }
  );
  return { vscode, state };
}

/**
 * Make require("vscode") give a fake with these settings; returns what it sees
 * (`errors` shown, `output` lines written).
 */
function installFakeVscode(settings, { folders = [], trusted = true } = {}) {
  const { vscode, state } = fakeVscode();
  Object.assign(state, { settings, folders, trusted });
  const load = Module._load;
  Module._load = function (request, ...rest) {
    return request === "vscode" ? vscode : load.call(this, request, ...rest);
  };
  return state;
}

module.exports = { installFakeVscode };
