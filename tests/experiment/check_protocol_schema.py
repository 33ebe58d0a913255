#!/usr/bin/python3
"""Validates every shipped protocol against docs/schema/texel-protocol.schema.json
(and the document schema it refers to for textures) with python3-jsonschema,
an implementation independent of Texel's own validator."""
import json
import pathlib
import sys

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
sys.exit(1 if failed else 0)
