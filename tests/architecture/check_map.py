#!/usr/bin/python3
"""Checks docs/architecture.md against what the build and the sources say
(the library table itself is check_library_graph.cmake's):

  components  the table between <!-- components begin/end -->: one row per
              TEXEL_WITH_* option of the build (cmake/TexelComponents.cmake),
              its libraries exactly those the option's help string names;
              with the core, every library in exactly one row;
  commands    the table between <!-- commands begin/end -->: one row per
              top-level `texel` command, found in apps/texel/ (each
              register_*() that main.cpp calls, the app.add_subcommand("...")
              in the function of that name), its source the file that
              defines it; every apps/texel/cmd_*.cpp named in some row; with
              --cli, `texel --help` lists the same commands;
  headers     every header under include/ is in one library's HEADERS file
              set; no installed header includes texel/detail/ or nlohmann;
              every installed header is named in the document (by file name,
              or by its directory for include/texel/<dir>/); the headers not
              installed are exactly those under the directories listed
              between <!-- not-installed begin/end -->.

usage: check_map.py --facts map_facts.txt --root <repository> --doc architecture.md [--cli texel]
       check_map.py ... --self-test   (mutates the document three ways; each must fail)

map_facts.txt is written at configure time (tests/architecture/CMakeLists.txt).
Stdlib only.
"""
import argparse
import os
import re
import subprocess
import sys


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def block(doc, name):
    m = re.search(r"<!-- %s begin -->(.*?)<!-- %s end -->" % (name, name), doc, re.S)
    if not m:
        raise SystemExit(f"architecture.md: no <!-- {name} begin --> … <!-- {name} end --> block")
    return m.group(1)


def table_rows(text):
    """Cells of each table row, header and separator rows left out."""
    rows = []
    for line in text.splitlines():
        line = line.strip()
        if not line.startswith("|") or re.match(r"^\|[-| :]+\|$", line):
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        if cells and cells[0].startswith("`"):
            rows.append(cells)
    return rows


def ticked(cell):
    return re.findall(r"`([^`]+)`", cell)


def load_facts(path):
    options, libraries, headers = {}, {}, {}
    for line in read(path).splitlines():
        kind, _, rest = line.partition(" ")
        if kind == "option":
            name, _, help_text = rest.partition(" ")
            options[name] = help_text
        elif kind == "library":
            name, component, installed = rest.split()
            libraries[name] = (component, installed == "installed")
        elif kind == "header":
            library, header = rest.split()
            headers.setdefault(header, []).append(library)
    return options, libraries, headers


def commands_in_sources(apps):
    """{command: file} of the top-level commands main.cpp registers."""
    main = read(os.path.join(apps, "main.cpp"))
    registered = set(re.findall(r"register_([a-z0-9_]+)\(app\)", main))
    # main.cpp's command table: {"name", &texel::cli::register_x}; the name must be the command x adds.
    table = dict(re.findall(r'\{\s*"([a-z0-9-]+)",\s*&texel::cli::register_([a-z0-9_]+)\s*\}', main))
    registered |= set(table.values())
    found, problems = {}, []
    defined = set()
    for name in sorted(os.listdir(apps)):
        if not name.endswith(".cpp"):
            continue
        text = read(os.path.join(apps, name))
        # Each register_X(CLI::App& app) function, up to the next one.
        starts = [(m.start(), m.group(1)) for m in re.finditer(r"void register_([a-z0-9_]+)\(CLI::App& *app\)", text)]
        for i, (at, function) in enumerate(starts):
            defined.add(function)
            if function not in registered:
                continue
            end = starts[i + 1][0] if i + 1 < len(starts) else len(text)
            for command in re.findall(r"\bapp\s*\.\s*add_subcommand\(\s*\"([a-z0-9-]+)\"", text[at:end]):
                if command in found:
                    problems.append(f"command {command} is added in {found[command]} and {name}")
                found[command] = name
    adds = {command: function for command, function in table.items()}
    for command, function in sorted(adds.items()):
        if command not in found:
            problems.append(f"main.cpp's command table names {command} for register_{function}, which adds no such command")
    for function in sorted(registered - defined):
        problems.append(f"main.cpp calls register_{function}(app), which no apps/texel/*.cpp defines as register_{function}(CLI::App& app)")
    return found, problems


def commands_in_help(cli):
    out = subprocess.run([cli, "--help"], capture_output=True, text=True, check=True).stdout
    m = re.search(r"^Subcommands:\n(.*?)(?:\n\S|\Z)", out, re.S | re.M | re.I)
    if not m:
        raise SystemExit(f"{cli} --help lists no SUBCOMMANDS:\n{out}")
    return {line.split()[0] for line in m.group(1).splitlines() if line.strip()}


def check(doc, facts, root, cli):
    options, libraries, headers = facts
    problems = []

    # --- components
    rows = table_rows(block(doc, "components"))
    documented = {}
    for cells in rows:
        option = ticked(cells[0])[0]
        documented[option] = sorted(set(ticked(cells[1]) if len(cells) > 1 else []))
    for option in sorted(set(options) - set(documented)):
        problems.append(f"components: the build has the option {option} ({options[option]}); add its row")
    for option in sorted(set(documented) - set(options)):
        problems.append(f"components: the table lists {option}, which is not a component option of the build")
    owner = {}
    for option in sorted(set(options) & set(documented)):
        named = sorted(set(re.findall(r"texel::[a-z0-9_]+", options[option].split(": ", 1)[0])))
        if named != documented[option]:
            problems.append(f"components: {option} builds {', '.join(named)} (its help string), the table says "
                            f"{', '.join(documented[option]) or 'nothing'}")
        for lib in documented[option]:
            if lib in owner:
                problems.append(f"components: {lib} is in the rows of {owner[lib]} and {option}")
            owner[lib] = option
    for lib in sorted(set(libraries) - set(owner) - {"texel::texel"}):
        problems.append(f"components: the library {lib} is in no component's row")

    # --- commands
    apps = os.path.join(root, "apps", "texel")
    in_sources, source_problems = commands_in_sources(apps)
    problems += ["commands: " + p for p in source_problems]
    rows = table_rows(block(doc, "commands"))
    documented = {}
    listed_files = set()
    for cells in rows:
        command = ticked(cells[0])[0]
        files = [f for f in ticked(cells[1]) if f.endswith(".cpp")] if len(cells) > 1 else []
        documented[command] = files
        listed_files.update(files)
    for command in sorted(set(in_sources) - set(documented)):
        problems.append(f"commands: `texel {command}` ({in_sources[command]}) has no row; add "
                        f"| `{command}` | `{in_sources[command]}` | … |")
    for command in sorted(set(documented) - set(in_sources)):
        problems.append(f"commands: the table lists `{command}`, which no registered function adds")
    for command in sorted(set(documented) & set(in_sources)):
        if not documented[command] or documented[command][0] != in_sources[command]:
            problems.append(f"commands: `{command}` is defined in {in_sources[command]}; its row's first source says "
                            f"{documented[command][0] if documented[command] else 'nothing'}")
    for name in sorted(os.listdir(apps)):
        if name.startswith("cmd_") and name.endswith(".cpp") and name not in listed_files:
            problems.append(f"commands: apps/texel/{name} is in no row of the commands table")
    for name in sorted(listed_files):
        if not os.path.exists(os.path.join(apps, name)):
            problems.append(f"commands: the table names apps/texel/{name}, which does not exist")
    if cli:
        in_help = commands_in_help(cli)
        if in_help != set(in_sources):
            problems.append(f"commands: `texel --help` lists {sorted(in_help)}, the sources register {sorted(in_sources)}")

    # --- headers
    include = os.path.join(root, "include")
    on_disk = set()
    for dirpath, _, files in os.walk(include):
        for f in files:
            if f.endswith((".h", ".hpp")):
                on_disk.add(os.path.relpath(os.path.join(dirpath, f), include))
    for h in sorted(on_disk - set(headers)):
        problems.append(f"headers: include/{h} is in no library's HEADERS file set (never installed, nor checked)")
    for h in sorted(set(headers) - on_disk):
        problems.append(f"headers: a HEADERS file set names include/{h}, which does not exist")
    not_installed_dirs = [d.rstrip("/") for d in ticked(block(doc, "not-installed")) if d.startswith("include/")]
    installed, not_installed = set(), set()
    for h, libs in headers.items():
        if any(libraries.get(lib, ("", True))[1] for lib in libs):
            installed.add(h)
        else:
            not_installed.add(h)
    for h in sorted(installed):
        text = read(os.path.join(include, h))
        for bad in ("texel/detail/", "nlohmann"):
            if re.search(r'^\s*#\s*include\s*[<"]%s' % re.escape(bad), text, re.M):
                problems.append(f"headers: the installed include/{h} includes {bad}")
        directory = os.path.dirname(h)
        named = re.search(r"(?<!\w)%s\b" % re.escape(os.path.basename(h)), doc) or (
            directory.count("/") >= 1 and f"include/{directory}/" in doc)
        if not named:
            problems.append(f"headers: the installed include/{h} is not named in architecture.md")
        if any(("include/" + h).startswith(d + "/") for d in not_installed_dirs):
            problems.append(f"headers: include/{h} is installed, but the document lists its directory as not installed")
    for h in sorted(not_installed):
        if not any(("include/" + h).startswith(d + "/") for d in not_installed_dirs):
            problems.append(f"headers: include/{h} is not installed; list its directory between <!-- not-installed --> markers")
    return problems, len(in_sources), len(options), len(installed)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--facts", required=True)
    p.add_argument("--root", required=True)
    p.add_argument("--doc")
    p.add_argument("--cli")
    p.add_argument("--self-test", action="store_true")
    a = p.parse_args()
    facts = load_facts(a.facts)
    doc_path = a.doc or os.path.join(a.root, "docs", "architecture.md")
    doc = read(doc_path)
    if a.self_test:
        # Each mutation of the true document must be reported.
        mutations = [
            ("a command row removed", re.sub(r"\n\| `render` \|[^\n]*", "", doc, count=1), "`texel render`"),
            ("an option row removed", re.sub(r"\n\| `TEXEL_WITH_SURFACE2D` \|[^\n]*", "", doc, count=1),
             "TEXEL_WITH_SURFACE2D"),
            ("a header's name removed", doc.replace("player_parts.hpp", "player_bits.hpp"), "player_parts.hpp"),
        ]
        failed = 0
        for what, mutated, expected in mutations:
            if mutated == doc:
                print(f"self-test: the document no longer has what '{what}' mutates; update check_map.py")
                failed += 1
                continue
            problems, *_ = check(mutated, facts, a.root, None)
            if not any(expected in q for q in problems):
                print(f"self-test: {what}: not reported (problems: {problems})")
                failed += 1
            else:
                print(f"self-test: {what}: reported")
        sys.exit(1 if failed else 0)
    problems, commands, options, installed = check(doc, facts, a.root, a.cli)
    for q in problems:
        print(f"{doc_path}: {q}")
    if problems:
        sys.exit(1)
    print(f"{doc_path}: {commands} commands, {options} component options and {installed} installed headers agree with the build")


if __name__ == "__main__":
    main()
