// folding.js: exsce folds by braces, block comments, runs of line comments and regions.
"use strict";

const assert = require("node:assert/strict");
const fs = require("node:fs");
const path = require("node:path");
const { test } = require("node:test");
const { foldingRanges } = require("../../folding");

test("each braced body folds, its closing brace staying visible", () => {
  const text = ["scenario s in e {", "  robots {", "    r1: t", "  }", "  mission m parallel {", "    r1 does t", "  }", "}"];
  assert.deepEqual(foldingRanges(text.join("\n")), [
    { start: 0, end: 6 },
    { start: 1, end: 2 },
    { start: 4, end: 5 },
  ]);
});

test("a body on one line or two does not fold", () => {
  assert.deepEqual(foldingRanges("robots { r1: t }\nrobots {\n}"), []);
});

test("braces in strings and comments are not bodies", () => {
  const text = [
    'metric m for each robot {',
    '  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"',
    "  // a } in a comment",
    "  /* and { in a block */",
    "  value max(vel.linear.x)",
    "}",
  ];
  assert.deepEqual(foldingRanges(text.join("\n")), [{ start: 0, end: 4 }]);
});

test("block comments, runs of line comments and regions fold", () => {
  const text = [
    "/* one",
    "   two */",
    "// a",
    "// b",
    "// region poses",
    "task t {",
    "  visit p",
    "}",
    "// endregion",
  ];
  assert.deepEqual(foldingRanges(text.join("\n")), [
    { start: 0, end: 1, kind: "comment" },
    { start: 2, end: 3, kind: "comment" },
    { start: 4, end: 8, kind: "region" },
    { start: 5, end: 6 },
  ]);
});

test("the shipped scenario_c folds at its declarations", () => {
  const file = path.resolve(__dirname, "..", "..", "..", "..", "examples", "brsu_building_c", "scenario_c.exsce");
  const ranges = foldingRanges(fs.readFileSync(file, "utf8"));
  const lines = fs.readFileSync(file, "utf8").split("\n");
  const starts = ranges.map((range) => lines[range.start].trim());
  assert.deepEqual(starts, [
    "scenario scenario_c in brsu_building_c_with_doors {",
    "robots {",
    "mission mission_c parallel {",
    "// What every run of scenario_c must show. The limits are the method's safety",
    "acceptance for scenario_c {",
    'scenario "moves safely" {',
    'scenario "performs as before" {',
    'scenario "delivers gently" {',
    'scenario "drives calmly" {',
  ]);
});
