#!/usr/bin/env python3
"""Validate every GLSL program that TreeLod's .program scripts declare with glslangValidator.

Each `glsl` program is compiled as GLSL 1.50 (RenderSystem_GL on a GL 3.2 driver) and 3.30
(GL3Plus), each `glsles` program as GLSL ES 3.00 (GLES2); vertex programs also with INSTANCED=1,
the variant the Forest derives. The source is prepared as OGRE 1.12 prepares it: includes resolved
from the materials folders, the leading version block (TreeLodShaderSupport.glsl) resolved for the
target, OGRE's built-in defines (OGRE_GLSL / OGRE_GLSLES, OGRE_VERTEX_SHADER / OGRE_FRAGMENT_SHADER,
GL_ES, which the ES compiler defines itself) and the program's preprocessor_defines added after the version line.

usage: validate-glsl.py MATERIALS_DIR [--validator PATH]
"""
import os
import re
import subprocess
import sys

from shader_sources import command_line, resolve_includes

VERSION_BLOCK = """#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
"""
TARGETS = {"glsl": [("GLSL 1.50", "#version 150", "OGRE_GLSL=150"),
                    ("GLSL 3.30", "#version 330 core", "OGRE_GLSL=330")],
           "glsles": [("GLSL ES 3.00", "#version 300 es", "OGRE_GLSLES=300")]}


def programs(materials):
    """(script, line, kind, name, language, source, defines) of every glsl/glsles program."""
    found = []
    for script in sorted(f for f in os.listdir(materials) if f.endswith(".program")):
        text = open(os.path.join(materials, script)).read()
        for m in re.finditer(r"^(vertex|fragment)_program\s+(\S+)\s+(glsl|glsles)\s*\{([^{}]*)\}", text, re.M):
            body = m.group(4)
            source = re.search(r"^\s*source\s+(\S+)", body, re.M)
            defines = re.search(r"^\s*preprocessor_defines\s+(\S+)", body, re.M)
            line = text.count("\n", 0, m.start()) + 1
            if not source:
                sys.exit("%s:%d: program %s has no source" % (script, line, m.group(2)))
            found.append((script, line, m.group(1), m.group(2), m.group(3), source.group(1),
                          defines.group(1) if defines else ""))
    return found


def main():
    materials, folders, validator = command_line(__doc__)
    checked, failures = 0, []
    found = programs(materials)
    if not found:
        sys.exit("no glsl or glsles program in %s/*.program" % materials)
    for script, line, kind, name, language, source, defines in found:
        where = "%s:%d %s (%s)" % (script, line, name, source)
        path = next((os.path.join(d, source) for d in folders if os.path.exists(os.path.join(d, source))), None)
        if not path:
            failures.append("%s: source not found" % where)
            continue
        text = resolve_includes(path, folders)
        if not text.startswith(VERSION_BLOCK):
            failures.append("%s: does not open with the version block of TreeLodShaderSupport.glsl" % where)
            continue
        body = text[len(VERSION_BLOCK):]
        variants = [defines]
        if kind == "vertex" and "INSTANCED" not in defines:
            variants.append(",".join(d for d in (defines, "INSTANCED=1") if d))
        for label, version, builtin in TARGETS[language]:
            for variant in variants:
                all_defines = [d for d in (builtin + ",OGRE_%s_SHADER" % kind.upper() + "," + variant).split(",") if d]
                header = version + "\n" + "".join("#define %s\n" % d.replace("=", " ", 1) for d in all_defines)
                # Error lines count from the line after the version block.
                prepared = header + "#line 1\n" + body
                run = subprocess.run([validator, "--stdin", "-S", "vert" if kind == "vertex" else "frag"],
                                     input=prepared, capture_output=True, text=True)
                checked += 1
                tag = "%s as %s%s" % (where, label, " with " + variant if variant else "")
                if run.returncode != 0:
                    failures.append("%s:\n%s" % (tag, (run.stdout + run.stderr).strip()))
                else:
                    print("ok   %s" % tag)
    for f in failures:
        print("FAIL " + f)
    print("%d compilations of %d programs, %d failed" % (checked, len(found), len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
