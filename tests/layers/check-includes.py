#!/usr/bin/env python3
"""The include graph's layers (docs/architecture.md, "Layout"): no cycle between folders or between
headers, and the shared layers (plugin/, samples/) include no technique's header. Run by ctest as
layers.includes; prints each offending include with its file and line and exits 1."""
import os
import re
import sys

root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
SCANNED = ("plugin", "techniques", "examples", "samples", "bench")
INCLUDE = re.compile(r'\s*#\s*include\s+"(?:TreeLod/)?([^"]+)"')


def folder(path):
    """plugin/core/<part>, plugin/<part>, techniques/<name>, examples/<name>, or the top folder."""
    parts = path.split("/")
    if parts[:2] == ["plugin", "core"]:
        return "/".join(parts[:3])
    if parts[0] in ("plugin", "techniques", "examples"):
        return "/".join(parts[:2])
    return parts[0]


files, headers = [], {}
for top in SCANNED:
    for directory, _, names in os.walk(os.path.join(root, top)):
        for name in names:
            if name.endswith((".h", ".cpp")):
                path = os.path.relpath(os.path.join(directory, name), root)
                files.append(path)
                if name.endswith(".h"):
                    headers.setdefault(name, []).append(path)

if not any(path.startswith("plugin/") for path in files) or not any(path.startswith("techniques/") for path in files):
    print(f"layers: no sources of plugin/ and techniques/ under {os.path.abspath(root)}")
    sys.exit(1)

edges = {}  # (from folder, to folder) -> first (file, line, header)
header_edges = {}
problems = []
for path in files:
    with open(os.path.join(root, path), errors="replace") as text:
        for number, line in enumerate(text, 1):
            match = INCLUDE.match(line)
            if not match:
                continue
            name = os.path.basename(match.group(1))
            targets = headers.get(name, [])
            if len(targets) != 1:
                continue  # not ours, or ambiguous by name (then the compiler's include path decides)
            target = targets[0]
            a, b = folder(path), folder(target)
            if a != b:
                edges.setdefault((a, b), (path, number, name))
                if a.startswith(("plugin", "samples")) and b.startswith("techniques/"):
                    problems.append(f"{path}:{number}: the shared layer {a} includes {name} of {b}")
            if path.endswith(".h"):
                header_edges.setdefault(path, set()).add(target)


def cycles(graph):
    """Each cycle once, as a list of nodes ending where it starts."""
    found, state = [], {}

    def visit(node, stack):
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                found.append(stack[stack.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, stack)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [])
    return found


folder_graph = {}
for a, b in edges:
    folder_graph.setdefault(a, set()).add(b)
for cycle in cycles(folder_graph):
    steps = [f"{a} -> {b} ({edges[(a, b)][0]}:{edges[(a, b)][1]} includes {edges[(a, b)][2]})"
             for a, b in zip(cycle, cycle[1:])]
    problems.append("folder cycle: " + "; ".join(steps))
for cycle in cycles(header_edges):
    problems.append("header cycle: " + " -> ".join(cycle))

for problem in problems:
    print(problem)
print(f"layers: {len(files)} files, {len(folder_graph)} folders with includes into others, "
      f"{len(problems)} problems")
sys.exit(1 if problems else 0)
