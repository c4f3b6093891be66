// Folding ranges of an exsce file: each braced body, each block comment, each run of
// line comments, and `// region` ... `// endregion`.  VS Code folds by indentation
// when no provider answers; exsce folds by braces.  No VS Code API here, so that it
// can be tested with plain node (test/unit/folding.test.js).
"use strict";

const REGION_START = /^\s*\/\/\s*#?region\b/;
const REGION_END = /^\s*\/\/\s*#?endregion\b/;
const LINE_COMMENT = /^\s*\/\//;

/**
 * @param {string} text
 * @returns {{start: number, end: number, kind?: "comment" | "region"}[]} zero-based lines,
 *   `end` the last line hidden (a body's closing brace stays visible)
 */
function foldingRanges(text) {
  const ranges = [];
  const braces = []; // lines of the `{` still open
  let line = 0;
  let state = "code"; // code | line-comment | block-comment | string
  let quote = "";
  let commentStart = 0;

  for (let i = 0; i < text.length; i++) {
    const c = text[i];
    const next = text[i + 1];
    if (c === "\n") {
      line++;
      if (state === "line-comment") state = "code";
      continue;
    }
    if (state === "line-comment") continue;
    if (state === "block-comment") {
      if (c === "*" && next === "/") {
        if (line > commentStart) ranges.push({ start: commentStart, end: line, kind: "comment" });
        state = "code";
        i++;
      }
      continue;
    }
    if (state === "string") {
      if (c === "\\") i++;
      else if (c === quote) state = "code";
      continue;
    }
    if (c === "/" && next === "/") {
      state = "line-comment";
      i++;
    } else if (c === "/" && next === "*") {
      state = "block-comment";
      commentStart = line;
      i++;
    } else if (c === '"' || c === "'") {
      state = "string";
      quote = c;
    } else if (c === "{") {
      braces.push(line);
    } else if (c === "}" && braces.length) {
      const start = braces.pop();
      if (line - 1 > start) ranges.push({ start, end: line - 1 });
    }
  }

  // Runs of line comments and regions, line by line.
  const lines = text.split("\n");
  const regions = [];
  let run = -1;
  lines.forEach((content, n) => {
    const isRegion = REGION_START.test(content) || REGION_END.test(content);
    if (REGION_START.test(content)) regions.push(n);
    else if (REGION_END.test(content) && regions.length) {
      ranges.push({ start: regions.pop(), end: n, kind: "region" });
    }
    const isComment = LINE_COMMENT.test(content) && !isRegion;
    if (isComment && run < 0) run = n;
    if (!isComment && run >= 0) {
      if (n - 1 > run) ranges.push({ start: run, end: n - 1, kind: "comment" });
      run = -1;
    }
  });
  if (run >= 0 && lines.length - 1 > run) ranges.push({ start: run, end: lines.length - 1, kind: "comment" });

  return ranges.sort((a, b) => a.start - b.start || b.end - a.end);
}

module.exports = { foldingRanges };
