#!/usr/bin/env python3
"""Compile every HLSL program that TreeLod's .program scripts declare with glslang's HLSL front end.

Each `hlsl` program is compiled as OGRE 1.12's RenderSystem_Direct3D11 would hand it to the D3D
compiler: includes resolved from the materials folders, OGRE's built-in defines (OGRE_HLSL=4,
OGRE_VERTEX_SHADER / OGRE_FRAGMENT_SHADER) and the program's preprocessor_defines, its
entry_point; vertex programs also with INSTANCED=1, the variant the Forest derives. The compiler
is `glslangValidator -D` (HLSL in, SPIR-V out): it parses and type-checks the program, it is not
Microsoft's fxc/D3DCompile and nothing here runs the result. Three checks glslang does not make:
- the target is a Shader Model 4 profile or higher (OGRE's default, vs/ps_4_0_level_9_1, lacks
  integer operations and texel fetches);
- no vector built from one scalar, `float3(0.0)`: glslang accepts it, fxc does not (the sources
  write vec3_splat);
- every texture's register is the texture unit the unified program's default_params give it
  (`param_named NAME int UNIT`, which the GLSL delegates use), and every such parameter names a
  texture of the HLSL program.

usage: validate-hlsl.py MATERIALS_DIR [--validator PATH]
"""
import os
import re
import subprocess
import sys

PROFILE = re.compile(r"^(vs|ps)_([4-9])_\d$")
SCALAR_CONSTRUCTOR = re.compile(r"\b(?:float|int|uint|bool)[234]\(\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?[uUfF]?\s*\)")
TEXTURE = re.compile(r"\bTexture\w*\s+(\w+)\s*:\s*register\(\s*t(\d+)\s*\)")


def blocks(text, kinds):
    """(kind, name, language, body, line) of the program blocks of a script."""
    for m in re.finditer(r"^(vertex|fragment)_program\s+(\S+)\s+(\S+)\s*\{((?:[^{}]|\{[^{}]*\})*)\}", text, re.M):
        if m.group(3) in kinds:
            yield m.group(1), m.group(2), m.group(3), m.group(4), text.count("\n", 0, m.start()) + 1


def resolve_includes(path, folders, seen=()):
    """The source with its includes inlined, #line directives keeping file names and lines."""
    out = ['#line 1 "%s"' % os.path.basename(path)]
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
        out.append(resolve_includes(hits[0], folders, seen + (hits[0],)))
        out.append('#line %d "%s"' % (n + 1, os.path.basename(path)))
    return "\n".join(out)


def main():
    args = sys.argv[1:]
    validator = "glslangValidator"
    if "--validator" in args:
        i = args.index("--validator")
        validator = args[i + 1]
        del args[i:i + 2]
    if len(args) != 1:
        sys.exit(__doc__)
    materials = args[0]
    folders = [materials, os.path.join(materials, "GLSL")]
    found, units = [], {}
    for script in sorted(f for f in os.listdir(materials) if f.endswith(".program")):
        text = open(os.path.join(materials, script)).read()
        for kind, name, language, body, line in blocks(text, ("hlsl", "unified")):
            if language == "unified":
                # The texture units of the unified program's samplers, for each HLSL delegate.
                params = dict(re.findall(r"^\s*param_named\s+(\w+)\s+int\s+(\d+)", body, re.M))
                for delegate in re.findall(r"^\s*delegate\s+(\S+)", body, re.M):
                    units[delegate] = (name, {k: int(v) for k, v in params.items()})
                continue
        for kind, name, language, body, line in blocks(text, ("hlsl",)):
            def option(key):
                m = re.search(r"^\s*%s\s+(\S+)" % key, body, re.M)
                return m.group(1) if m else ""
            found.append((script, line, kind, name, option("source"), option("preprocessor_defines"),
                          option("entry_point") or "main", option("target")))
    if not found:
        sys.exit("no hlsl program in %s/*.program" % materials)
    checked, failures = 0, []
    for script, line, kind, name, source, defines, entry, target in found:
        where = "%s:%d %s (%s)" % (script, line, name, source)
        profile = PROFILE.match(target)
        if not profile or profile.group(1) != ("vs" if kind == "vertex" else "ps"):
            failures.append("%s: target '%s' is not a %s_4_0 or higher profile" % (where, target, "vs" if kind == "vertex" else "ps"))
        if name not in units:
            failures.append("%s: no unified program delegates to it" % where)
        path = next((os.path.join(d, source) for d in folders if os.path.exists(os.path.join(d, source))), None)
        if not path:
            failures.append("%s: source not found" % where)
            continue
        text = resolve_includes(path, folders)
        variants = [defines]
        if kind == "vertex" and "INSTANCED" not in defines:
            variants.append(",".join(d for d in (defines, "INSTANCED=1") if d))
        for variant in variants:
            all_defines = [d for d in ("OGRE_HLSL=4,OGRE_%s_SHADER," % kind.upper() + variant).split(",") if d]
            command = [validator, "--stdin", "-S", "vert" if kind == "vertex" else "frag", "-D", "-e", entry]
            command += ["-D" + d for d in all_defines]
            tag = "%s as HLSL %s%s" % (where, target, " with " + variant if variant else "")
            checked += 1
            run = subprocess.run(command + ["-V", "-o", os.devnull], input=text, capture_output=True, text=True)
            if run.returncode != 0:
                failures.append("%s:\n%s" % (tag, (run.stdout + run.stderr).strip()))
                continue
            pre = subprocess.run(command + ["-E"], input=text, capture_output=True, text=True)
            if pre.returncode != 0:
                failures.append("%s: preprocessing failed:\n%s" % (tag, (pre.stdout + pre.stderr).strip()))
                continue
            problems = ["vector from one scalar (fxc rejects it; write vecN_splat): " + m.group(0)
                        for m in SCALAR_CONSTRUCTOR.finditer(pre.stdout)]
            textures = {t: int(u) for t, u in TEXTURE.findall(pre.stdout)}
            if name in units:
                unified, params = units[name]
                derived = variant != defines  # the Forest's INSTANCED variant sets its own extra units
                for texture, unit in sorted(textures.items()):
                    if derived and texture not in params:
                        continue
                    if params.get(texture) != unit:
                        problems.append("texture %s in register t%d, %s's default_params give unit %s"
                                        % (texture, unit, unified, params.get(texture, "none")))
                for param, unit in sorted(params.items()):
                    if param not in textures:
                        problems.append("%s's default_params set %s = %d, no texture of that name"
                                        % (unified, param, unit))
            if problems:
                failures.append("%s:\n  %s" % (tag, "\n  ".join(problems)))
            else:
                print("ok   %s" % tag)
    for f in failures:
        print("FAIL " + f)
    print("%d compilations of %d programs, %d failed" % (checked, len(found), len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
