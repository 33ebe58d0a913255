#!/usr/bin/python3
"""Validates WebSocket frames the browser tests recorded (JSON lines
{"dir": "sent"|"received", "text": ...}) against the message schema,
docs/schema/studio-messages.schema.json: every message the page sent must be
a ClientMessage, every one the studio answered a ServerMessage. Uses
python3-jsonschema, an implementation independent of both the service and
the TypeScript generator.

  check_messages.py REPO_ROOT FRAMES.jsonl
"""
import json
import pathlib
import sys
import warnings

import jsonschema

warnings.simplefilter("ignore", DeprecationWarning)  # RefResolver, as in tests/experiment/check_protocol_schema.py

root = pathlib.Path(sys.argv[1])
schemas = root / "docs" / "schema"
load = lambda n: json.loads((schemas / n).read_text())
messages = load("studio-messages.schema.json")
store = {n: load(n) for n in ("texel-document.schema.json", "texel-protocol.schema.json", "studio-messages.schema.json")}
jsonschema.Draft202012Validator.check_schema(messages)
resolver = jsonschema.RefResolver.from_schema(messages, store=store)


def validator(name):
    return jsonschema.Draft202012Validator({"$ref": f"studio-messages.schema.json#/$defs/{name}"}, resolver=resolver)


# Each message against its own definition (by type), so an error names the field.
by_dir = {}
for d, union in (("sent", "ClientMessage"), ("received", "ServerMessage")):
    by_dir[d] = {}
    for ref in messages["$defs"][union]["oneOf"]:
        name = ref["$ref"].split("/")[-1]
        by_dir[d][messages["$defs"][name]["properties"]["type"]["const"]] = validator(name)
counts, failed, seen = {"sent": 0, "received": 0}, 0, set()
for line in pathlib.Path(sys.argv[2]).read_text().splitlines():
    frame = json.loads(line)
    msg = json.loads(frame["text"])
    counts[frame["dir"]] += 1
    seen.add((frame["dir"], msg.get("type")))
    v = by_dir[frame["dir"]].get(msg.get("type"))
    errors = list(v.iter_errors(msg)) if v else [f"type {msg.get('type')!r} is no {frame['dir']} message of the schema"]
    if errors:
        failed += 1
        if failed <= 5:
            e = errors[0] if not v else jsonschema.exceptions.best_match(errors)
            where = "" if not v else "/".join(map(str, e.absolute_path)) + ": "
            print(f"{frame['dir']} {msg.get('type')}: {where}{e if not v else e.message[:300]}")
types = ", ".join(sorted(f"{d[0]}:{t}" for d, t in seen))
print(f"{counts['sent']} sent and {counts['received']} received messages, {failed} not as the schema says ({types})")
sys.exit(1 if failed else 0)
