"""Texel's .hjif against the published MPEG-I Haptics JSON schemas.

Run by ctest (interchange.schema) with Debian's /usr/bin/python3:

    schema_conformance.py TOOL WORKDIR

TOOL is tests/interchange/conformance_tool.cpp built. The schemas and the
reference software's files are third-party test data read from
$TEXEL_THIRD_PARTY (.ci/run sets it); without it the test exits 77, which
ctest reports as skipped, after saying so.

Checks, with python3-jsonschema's Draft4Validator (the schemas' $schema) and a
FormatChecker whose date-time is RFC 3339 (python3-rfc3339: jsonschema 4.10
checks date-time only through rfc3339-validator, which Debian does not
package):

1. every kind of file Texel writes (fine, coarse, quantized, two regions,
   reference, generic grid, vibrotactile texture) is valid and Texel's own
   checker (hjif::conformance_errors) finds it conformant;
2. on 200 files mutated field by field from them (their effects cut to 12
   keyframes), Texel's schema checker
   (hjif::schema_errors) and the validator give the same verdict;
3. the reference software's own .hjif files get the same verdict from both
   (its date form, 2026-11-26 14:06:29, is not RFC 3339: both refuse it).
"""
import copy
import json
import os
import random
import subprocess
import sys

try:
    import jsonschema
    from pyrfc3339 import parse as parse_rfc3339
except ImportError as e:  # pragma: no cover - a machine without the Debian packages
    print(f"SKIPPED: {e} (scripts/install-deps.sh installs python3-jsonschema and python3-rfc3339)")
    sys.exit(77)


def validator(schemas: str) -> jsonschema.Draft4Validator:
    store = {}
    for name in os.listdir(schemas):
        if name.endswith(".json"):
            with open(os.path.join(schemas, name), encoding="utf-8") as f:
                store[name] = json.load(f)
    root = store["MPEG_haptics.schema.json"]
    base = "file://" + os.path.abspath(schemas) + "/"
    full_store = {base + k: v for k, v in store.items()}
    resolver = jsonschema.RefResolver(base_uri=base + "MPEG_haptics.schema.json", referrer=root, store=full_store)
    checker = jsonschema.FormatChecker()

    @checker.checks("date-time", raises=(ValueError, TypeError))
    def _date_time(instance):
        if not isinstance(instance, str):
            return True
        parse_rfc3339(instance)
        return True

    return jsonschema.Draft4Validator(root, resolver=resolver, format_checker=checker)


def verdicts(tool: str, paths):
    out = {}
    for i in range(0, len(paths), 50):
        res = subprocess.run([tool, "check", *paths[i:i + 50]], check=True, capture_output=True, text=True)
        for line in res.stdout.splitlines():
            path, schema, conformance, first = (line.split("\t") + [""])[:4]
            out[path] = (schema == "valid", conformance == "conformant", first)
    return out


# --- mutations: one field at a time, aimed at the schemas' keywords ------------------

REPLACEMENTS = [
    -1, 0, 1, 2, 16, 255, 256, 6.3, 10001, -127, 128, 4294967296, 1.5, 0.5, -0.5, 2.0, "", "x", "Main",
    "2026-11-26", "2026-11-26 14:06:29", "2026-11-26T14:06:29Z", "2026-13-01T00:00:00Z", "2023", "2023-1",
    "2023-10", "Linear", "BSpline", "Bspline", "Friction", "Sine", "Basis", "LRA", None, True, [], {}, [{}],
]


def nodes(value, path=()):
    yield path, value
    if isinstance(value, dict):
        for k, v in value.items():
            yield from nodes(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value[:3]):  # keyframe arrays are long: their first items stand for the rest
            yield from nodes(v, path + (i,))


def get(doc, path):
    for p in path:
        doc = doc[p]
    return doc


def mutate(doc, rng):
    m = copy.deepcopy(doc)
    candidates = [p for p, _ in nodes(m) if p]
    path = rng.choice(candidates)
    parent = get(m, path[:-1])
    key = path[-1]
    action = rng.random()
    if action < 0.2 and isinstance(parent, dict):
        del parent[key]  # a required field missing, or an optional one
    elif action < 0.3 and isinstance(parent, dict):
        parent[rng.choice(["priority", "block_length", "phase", "id", "timescale", "mesh", "type", "custom"])] = \
            rng.choice(REPLACEMENTS)
    else:
        parent[key] = rng.choice(REPLACEMENTS)
    return m


def main():
    tool, work = sys.argv[1], sys.argv[2]
    third = os.environ.get("TEXEL_THIRD_PARTY", "")
    schemas = os.path.join(third, "mpeg-haptics-schemas")
    if not third or not os.path.isdir(schemas):
        print("SKIPPED: set TEXEL_THIRD_PARTY to the third-party folder (with mpeg-haptics-schemas/) to run the schema tests")
        sys.exit(77)
    v = validator(schemas)
    os.makedirs(work, exist_ok=True)
    subprocess.run([tool, "write", work], check=True)
    written = sorted(os.path.join(work, f) for f in os.listdir(work) if f.endswith(".hjif") and not f.startswith("m"))
    assert len(written) >= 7, written
    texel = verdicts(tool, written)
    failures = []
    for path in written:
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
        errors = [f"{'/'.join(map(str, e.absolute_path))}: {e.message}" for e in v.iter_errors(doc)]
        if errors:
            failures.append(f"{os.path.basename(path)} fails the published schema: {errors[0]}")
        schema_ok, conformant, first = texel[path]
        if not (schema_ok and conformant):
            failures.append(f"{os.path.basename(path)} fails Texel's checker: {first}")
    print(f"{len(written)} files Texel writes: valid against the published schemas (format-checked) and conformant")

    # 200 mutated files: the two schema readings agree.
    rng = random.Random(24)
    sources = [json.load(open(p, encoding="utf-8")) for p in written]
    # Each effect keeps its first 12 keyframes: the mutations aim at fields, and a validator
    # walking 18,000 keyframes per file through $ref would take minutes for 200 files.
    for doc in sources:
        for p in doc["perceptions"]:
            for c in p["channels"]:
                for b in c["bands"]:
                    for e in b["effects"]:
                        e["keyframes"] = e["keyframes"][:12]
    mutated = []
    for k in range(200):
        doc = mutate(rng.choice(sources), rng)
        path = os.path.join(work, f"m{k:03d}.hjif")
        with open(path, "w", encoding="utf-8") as f:
            json.dump(doc, f)
        mutated.append((path, doc))
    texel = verdicts(tool, [p for p, _ in mutated])
    refused = 0
    for path, doc in mutated:
        errors = list(v.iter_errors(doc))
        ok = not errors
        refused += not ok
        if texel[path][0] != ok:
            failures.append(f"{os.path.basename(path)}: the validator says {'valid' if ok else 'invalid: ' + errors[0].message}, "
                            f"Texel's schema_errors says {'valid' if texel[path][0] else 'invalid'}")
    print(f"200 mutated files: {refused} invalid, {200 - refused} valid; Texel and the validator agree on "
          f"{200 - sum(1 for f in failures if f.startswith('m'))}")

    # The reference software's files.
    rm = os.path.join(third, "mpeg-haptics-rm-outputs")
    if os.path.isdir(rm):
        files = sorted(os.path.join(rm, f) for f in os.listdir(rm) if f.endswith(".hjif"))
        texel = verdicts(tool, files)
        for path in files:
            with open(path, encoding="utf-8") as f:
                errors = list(v.iter_errors(json.load(f)))
            ok = not errors
            print(f"{os.path.basename(path)}: validator {'valid' if ok else 'invalid (' + errors[0].message + ')'}, "
                  f"Texel {'valid' if texel[path][0] else 'invalid (' + texel[path][2] + ')'}")
            if texel[path][0] != ok:
                failures.append(f"{os.path.basename(path)}: the validator and Texel disagree")
    for f in failures:
        print("FAIL:", f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
