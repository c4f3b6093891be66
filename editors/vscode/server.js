// Where the exsce language server is: the `exsce.server.command` setting made
// into a program that exists.  No VS Code API here, so that it can be tested
// with plain node (test/unit/server.test.js).
"use strict";

const fs = require("fs");
const os = require("os");
const path = require("path");

/** The command could not be found; `message` says what was tried and what to do. */
class ServerNotFound extends Error {
  constructor(command, tried) {
    super(
      `exsce: cannot start the language server: '${command}' was not found ` +
        `(looked for ${tried.join(", ")}). ` +
        "Install exsce in the Python environment you work in (pip install exsce), " +
        "or set \"exsce.server.command\" to the full path of exscec, " +
        "for instance /path/to/project/.venv/bin/exscec."
    );
    this.name = "ServerNotFound";
    this.command = command;
    this.tried = tried;
  }
}

/**
 * `${workspaceFolder}`, `${userHome}`, `${env:NAME}` and a leading `~` in a setting, replaced.
 * A `${workspaceFolder}` with no folder open is left as it is (and will not be found).
 */
function expandVariables(value, { workspaceFolders = [], env = process.env, home = os.homedir() } = {}) {
  let expanded = value.replace(/\$\{(workspaceFolder|userHome|env:([A-Za-z_][A-Za-z0-9_]*))\}/g, (all, name, envName) => {
    if (name === "workspaceFolder") return workspaceFolders.length ? workspaceFolders[0] : all;
    if (name === "userHome") return home;
    return env[envName] || "";
  });
  if (expanded === "~" || expanded.startsWith("~/") || expanded.startsWith("~\\")) {
    expanded = path.join(home, expanded.slice(1));
  }
  return expanded;
}

function isExecutableFile(file, platform) {
  try {
    if (!fs.statSync(file).isFile()) return false;
    if (platform !== "win32") fs.accessSync(file, fs.constants.X_OK);
    return true;
  } catch {
    return false;
  }
}

/** The names a program may have on disk: on Windows with each of PATHEXT's extensions. */
function candidateNames(command, platform, env) {
  if (platform !== "win32" || path.extname(command)) return [command];
  const extensions = (env.PATHEXT || ".COM;.EXE;.BAT;.CMD").split(";").filter(Boolean);
  return [command, ...extensions.map((ext) => command + ext.toLowerCase())];
}

/** Virtual environments in a workspace folder where `exscec` is commonly installed. */
function workspaceEnvironments(folder, platform) {
  const bin = platform === "win32" ? "Scripts" : "bin";
  return [".venv", "venv"].map((env) => path.join(folder, env, bin));
}

/**
 * The language server's program and arguments.
 *
 * `command` is a path (absolute, or relative to the first workspace folder) or a bare name
 * looked up on PATH.  When it is a bare name missing from PATH, and the workspace is
 * trusted, the workspace's own virtual environment (.venv or venv) is tried, since that
 * is where a project installs exsce.  Throws ServerNotFound when nothing is found.
 *
 * @returns {{command: string, args: string[], source: string}}
 */
function resolveServer({
  command = "exscec",
  args = ["lsp"],
  workspaceFolders = [],
  trusted = false,
  env = process.env,
  platform = process.platform,
  home = os.homedir(),
} = {}) {
  const wanted = expandVariables(String(command).trim() || "exscec", { workspaceFolders, env, home });
  const expandedArgs = args.map((arg) => expandVariables(String(arg), { workspaceFolders, env, home }));
  const tried = [];
  const found = (file, source) => ({ command: file, args: expandedArgs, source });

  const isPath = wanted.includes("/") || (platform === "win32" && wanted.includes("\\"));
  if (isPath) {
    const base = workspaceFolders.length ? workspaceFolders[0] : process.cwd();
    const absolute = path.isAbsolute(wanted) ? wanted : path.resolve(base, wanted);
    for (const file of candidateNames(absolute, platform, env)) {
      tried.push(file);
      if (isExecutableFile(file, platform)) return found(file, "exsce.server.command");
    }
    throw new ServerNotFound(wanted, tried);
  }

  const pathDirs = (env.PATH || env.Path || "").split(path.delimiter).filter(Boolean);
  for (const dir of pathDirs) {
    for (const file of candidateNames(path.join(dir, wanted), platform, env)) {
      if (isExecutableFile(file, platform)) return found(file, "PATH");
    }
  }
  tried.push(`'${wanted}' on PATH`);

  if (trusted) {
    for (const folder of workspaceFolders) {
      for (const dir of workspaceEnvironments(folder, platform)) {
        for (const file of candidateNames(path.join(dir, wanted), platform, env)) {
          tried.push(file);
          if (isExecutableFile(file, platform)) return found(file, "the workspace's virtual environment");
        }
      }
    }
  }
  throw new ServerNotFound(wanted, tried);
}

module.exports = { resolveServer, expandVariables, ServerNotFound };
