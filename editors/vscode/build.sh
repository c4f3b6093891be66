#!/bin/sh
# Build the exsce VS Code extension: install the locked dependencies, run the
# grammar, snapshot and unit tests, and write exsce-<version>.vsix beside this file.
set -eu
cd "$(dirname "$0")"
npm ci --no-audit --no-fund
npm test
npm run package
