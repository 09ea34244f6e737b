"""Shared by validate-glsl.py and validate-hlsl.py: a program's source as OGRE hands it to the compiler."""
import os
import re
import sys


def resolve_includes(path, folders, line_markers=False, seen=()):
    """The source at `path` with its #include lines inlined from `folders` (the first that holds the
    file); with line_markers, `#line N "FILE"` directives keep file names and lines in messages
    (HLSL's form: GLSL's #line takes no file name)."""
    out = ['#line 1 "%s"' % os.path.basename(path)] if line_markers else []
    for n, line in enumerate(open(path).read().split("\n"), 1):
        m = re.match(r'\s*#include\s+[<"]([^>"]+)[>"]', line)
        if not m:
            out.append(line)
            continue
        hits = [os.path.join(d, m.group(1)) for d in folders if os.path.exists(os.path.join(d, m.group(1)))]
        if not hits:
            raise ValueError("%s:%d: #include %s: not in %s" % (path, n, m.group(1), ", ".join(folders)))
        if hits[0] in seen:
            raise ValueError("%s:%d: #include %s: included recursively" % (path, n, m.group(1)))
        out.append(resolve_includes(hits[0], folders, line_markers, seen + (hits[0],)))
        if line_markers:
            out.append('#line %d "%s"' % (n + 1, os.path.basename(path)))
    return "\n".join(out)


def command_line(usage):
    """(materials folder, folders includes come from, validator) from `MATERIALS_DIR [--validator PATH]`."""
    args = sys.argv[1:]
    validator = "glslangValidator"
    if "--validator" in args:
        i = args.index("--validator")
        validator = args[i + 1]
        del args[i:i + 2]
    if len(args) != 1:
        sys.exit(usage)
    materials = args[0]
    return materials, [materials, os.path.join(materials, "GLSL")], validator
