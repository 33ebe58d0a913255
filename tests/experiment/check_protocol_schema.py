#!/usr/bin/python3
"""Validates every shipped protocol against docs/schema/texel-protocol.schema.json
(and the document schema it refers to for textures) with python3-jsonschema,
an implementation independent of Texel's own validator.

  check_protocol_schema.py REPO_ROOT [TEXEL_CLI]

With the texel binary, also a set of broken protocols (one mistake each) that
the schema rejects must be refused by the engine's own validation (what the
studio's protocol editor and every front door use): `texel experiment run`
exits 2 with one line, before any trial."""
import copy
import json
import pathlib
import subprocess
import sys
import tempfile

import jsonschema

root = pathlib.Path(sys.argv[1])
schemas = root / "docs" / "schema"
protocol_schema = json.loads((schemas / "texel-protocol.schema.json").read_text())
document_schema = json.loads((schemas / "texel-document.schema.json").read_text())
store = {"texel-protocol.schema.json": protocol_schema, "texel-document.schema.json": document_schema}
resolver = jsonschema.RefResolver.from_schema(protocol_schema, store=store)
validator = jsonschema.Draft202012Validator(protocol_schema, resolver=resolver)
jsonschema.Draft202012Validator.check_schema(protocol_schema)
failed = 0
files = sorted((root / "examples" / "protocols").glob("*.json"))
for f in files:
    errors = sorted(validator.iter_errors(json.loads(f.read_text())), key=lambda e: list(e.path))
    for e in errors[:3]:
        print(f"{f.name}: {'/'.join(map(str, e.path))}: {e.message[:300]}")
    failed += bool(errors)
# A broken protocol must fail the schema too (the check can fail).
bad = json.loads(files[0].read_text())
bad["blocks"][0]["task"] = "dance"
if not list(validator.iter_errors(bad)):
    print("schema accepted a block with task 'dance'")
    failed += 1
print(f"{len(files) - failed} passed, {failed} failed")

if len(sys.argv) > 2:
    base = json.loads((root / "examples" / "protocols" / "texel-length.json").read_text())

    def top(key, value):
        return lambda p: p.__setitem__(key, value)

    def block(key, value):
        return lambda p: p["blocks"][0].__setitem__(key, value)

    def texture(key, value):
        return lambda p: p["blocks"][0]["texture"].__setitem__(key, value)

    cases = {
        "format": top("format", "texel-document"),
        "version": top("version", 99),
        "name pattern": top("name", "a name with spaces!"),
        "study": top("study", "astrology"),
        "seed below 0": top("seed", -1),
        "unknown key": top("colour", "blue"),
        "no blocks": top("blocks", []),
        "task": block("task", "dance"),
        "block name empty": block("name", ""),
        "time limit below 0": block("time_limit_s", -1),
        "time limit above 3600": block("time_limit_s", 4000),
        "display below 0": block("display_mm", -5),
        "unknown block key": block("speed", 3),
        "texture kind": texture("kind", "marble"),
        "pitch above the range": texture("central_pitch_db", 99),
        "texture not an object": block("texture", "fine"),
    }
    engine_failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        for label, edit in cases.items():
            bad = copy.deepcopy(base)
            edit(bad)
            if not list(validator.iter_errors(bad)):
                print(f"{label}: the schema accepted it")
                engine_failed += 1
                continue
            path = pathlib.Path(tmp) / "bad.json"
            path.write_text(json.dumps(bad))
            db = pathlib.Path(tmp) / "s.db"
            r = subprocess.run([sys.argv[2], "experiment", "run", str(path), "--participant", "T1", "--db", str(db),
                                "--simulate", "default"], capture_output=True, text=True, timeout=120)
            lines = r.stderr.strip().splitlines()
            if r.returncode != 2 or len(lines) != 1:
                print(f"{label}: the schema rejects it, the engine exited {r.returncode}: {r.stderr.strip()[:300]}")
                engine_failed += 1
            else:
                print(f"{label}: both reject it ({lines[0][:160]})")
    print(f"{len(cases) - engine_failed} of {len(cases)} broken protocols refused by schema and engine alike")
    failed += engine_failed
sys.exit(1 if failed else 0)
