#!/usr/bin/env node
// Snapshot tests of the shipped examples with vscode-tmgrammar-snap: every token of
// every shipped .exsce file and its scopes, as recorded in test/snap/.
//
//   node test/snapshots.js            check the examples against test/snap/
//   node test/snapshots.js --update   rewrite test/snap/ (review the diff)
//
// The tool writes each .snap beside its input, and the examples' folders are not the
// editor's; so it runs on copies in a temporary folder, where the recorded .snap
// files are put beside them, and only the .snap files are kept here.
"use strict";

const { spawnSync } = require("child_process");
const fs = require("fs");
const os = require("os");
const path = require("path");

const EXTENSION = path.resolve(__dirname, "..");
const REPOSITORY = path.resolve(EXTENSION, "..", "..");
const RECORDED = path.join(__dirname, "snap");
const TOOL = path.join(EXTENSION, "node_modules", "vscode-tmgrammar-test", "dist", "snapshot.js");

// The shipped .exsce files, by folder of test/snap/.
const EXAMPLES = {
  brsu_building_c: "examples/brsu_building_c",
  drones: "examples/drones",
  stdlib: "src/exsce_dsl/lang/stdlib",
};

function files(dir, suffix) {
  if (!fs.existsSync(dir)) return [];
  return fs.readdirSync(dir, { withFileTypes: true }).flatMap((entry) => {
    const full = path.join(dir, entry.name);
    if (entry.isDirectory()) return files(full, suffix);
    return entry.name.endsWith(suffix) ? [full] : [];
  });
}

/** Each example as [its path in test/snap/ without .snap, its path in the repository]. */
function examples() {
  return Object.entries(EXAMPLES).flatMap(([folder, source]) =>
    files(path.join(REPOSITORY, source), ".exsce").map((file) => [
      path.join(folder, path.relative(path.join(REPOSITORY, source), file)),
      file,
    ])
  );
}

function copy(from, to) {
  fs.mkdirSync(path.dirname(to), { recursive: true });
  fs.copyFileSync(from, to);
}

const update = process.argv.includes("--update");
const work = fs.mkdtempSync(path.join(os.tmpdir(), "exsce-snap-"));
const wanted = examples();
const problems = [];

for (const [name, source] of wanted) {
  copy(source, path.join(work, name));
  const recorded = path.join(RECORDED, name + ".snap");
  if (fs.existsSync(recorded)) copy(recorded, path.join(work, name + ".snap"));
  else if (!update) problems.push(`no snapshot of ${path.relative(REPOSITORY, source)}`);
}
const names = new Set(wanted.map(([name]) => name + ".snap"));
for (const stale of files(RECORDED, ".snap")) {
  const name = path.relative(RECORDED, stale);
  if (names.has(name)) continue;
  if (update) fs.rmSync(stale);
  else problems.push(`test/snap/${name} is the snapshot of no shipped example`);
}

const args = [TOOL, "--config", path.join(EXTENSION, "package.json"), ...(update ? ["--updateSnapshot"] : [])];
const run = spawnSync(process.execPath, [...args, ...wanted.map(([name]) => name)], { cwd: work, encoding: "utf8" });
// Say which example, not which copy.
const where = new RegExp(`(^|\\s)(${Object.keys(EXAMPLES).join("|")})/`, "gm");
process.stdout.write((run.stdout || "").replace(where, (_all, space, folder) => `${space}${EXAMPLES[folder]}/`));
process.stderr.write(run.stderr || "");

if (update && run.status === 0) {
  for (const [name] of wanted) copy(path.join(work, name + ".snap"), path.join(RECORDED, name + ".snap"));
}
fs.rmSync(work, { recursive: true, force: true });
for (const problem of problems) console.error(`ERROR ${problem}: run npm run snap:update`);
process.exit(run.status === 0 && problems.length === 0 ? 0 : 1);
