#!/usr/bin/env bash
# Is there a Node.js >= 20 with npm, as Texel Studio's front end needs
# (web/: Vite; Debian 12's own nodejs, 18, is too old)? Only the front end
# needs it: the C++ libraries, the C library, the CLI and the Python package
# build without Node.
#
#   scripts/check-node.sh          exit 2 with what needs it, when missing (make web, demo, test, bench)
#   scripts/check-node.sh --note   a note on stderr when missing, exit 0 (scripts/install-deps.sh)
set -uo pipefail
if command -v node >/dev/null && command -v npm >/dev/null &&
   node -e 'process.exit(Number(process.versions.node.split(".")[0]) < 20 ? 1 : 0)' 2>/dev/null; then
  exit 0
fi
found="$(node --version 2>/dev/null || echo none)$(command -v npm >/dev/null || echo ', no npm')"
if [ "${1:-}" = "--note" ]; then
  echo "install-deps: note: no Node.js >= 20 with npm (found: $found): the libraries, the CLI and the Python package" \
       "build; Texel Studio's front end (make web, demo, test, bench) needs it." >&2
  exit 0
fi
echo "Node.js >= 20 with npm is needed to build Texel Studio's front end, which make web, demo, test and bench use" \
     "(found: $found). Install it (https://nodejs.org, or NodeSource's Debian packages); make build, make cli," \
     "make python and make wheel work without it." >&2
exit 2
