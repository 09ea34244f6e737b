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

Then the linkage of the stages, which Direct3D 11 checks when it draws: in every pass of the
.material scripts that names a vertex and a fragment program, the fragment program's inputs must
be the vertex program's outputs, in the same order, with the same semantics (name and index,
TEXCOORD = TEXCOORD0), types and interpolation modifiers (`nointerpolation` from FLAT_OUT /
FLAT_IN): TreeLodShaderSupport.glsl's convention, stricter than Direct3D, which lets a pixel
shader read fewer components or a packed prefix. Both sides are main's parameters in the
preprocessed text the compile step makes (`glslangValidator -D -E`, same defines); SV_Position
and the values the rasteriser makes (SV_IsFrontFace, SV_SampleIndex, SV_PrimitiveID,
SV_Coverage) are left out wherever they are declared, and the messages count the others from 0.
The vertex side is checked as declared and as the Forest's INSTANCED=1 variant
("<name>/Instanced", Forest.cpp instancedProgram; the Forest derives it for every pass of the
materials it draws, here it is checked for every pass; a program whose defines have INSTANCED is
its own variant). A material's program names resolve to the hlsl programs: a unified program to
its first hlsl delegate, with that delegate's preprocessor_defines. Material scripts are read as
OGRE 1.12's script compiler reads them: `: base` inheritance (the base's objects overlaid into the
object, named children matched by class and name, unnamed ones by class and position), abstract
objects, a pass's last vertex_program_ref / fragment_program_ref winning. Not handled:
shadow_caster_* / shadow_receiver_*_program_ref (no script uses them; shadow caster materials
are materials, checked as such), `import`, `$variables`, wildcard names, bases in another script,
and materials made or reprogrammed in C++ (the clones of TreeAsset and the *Resources classes
keep the scripts' programs; the Forest's instanced clone is the variant above).

usage: validate-hlsl.py MATERIALS_DIR [--validator PATH]
"""
import os
import re
import subprocess
import sys

from shader_sources import command_line, resolve_includes

PROFILE = re.compile(r"^(vs|ps)_([4-9])_\d$")
SCALAR_CONSTRUCTOR = re.compile(r"\b(?:float|int|uint|bool)[234]\(\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?[uUfF]?\s*\)")
TEXTURE = re.compile(r"\bTexture\w*\s+(\w+)\s*:\s*register\(\s*t(\d+)\s*\)")


def blocks(text, kinds):
    """(kind, name, language, body, line) of the program blocks of a script."""
    for m in re.finditer(r"^(vertex|fragment)_program\s+(\S+)\s+(\S+)\s*\{((?:[^{}]|\{[^{}]*\})*)\}", text, re.M):
        if m.group(3) in kinds:
            yield m.group(1), m.group(2), m.group(3), m.group(4), text.count("\n", 0, m.start()) + 1


class ScriptObject:
    """An object of an OGRE script: `[abstract] CLS [NAME] [: BASE...] { ... }`; children are objects only."""

    def __init__(self, cls, name, bases, abstract, line):
        self.cls, self.name, self.bases, self.abstract, self.line = cls, name, bases, abstract, line
        self.children = []

    def clone(self):
        copy = ScriptObject(self.cls, self.name, self.bases, self.abstract, self.line)
        copy.children = [c.clone() for c in self.children]
        return copy


def script_objects(text):
    """The top-level objects of an OGRE script (properties skipped: no check reads them).

    Statements end at a line's end; a statement followed by `{` is an object's header."""
    text = re.sub(r"/\*.*?\*/", lambda m: re.sub(r"[^\n]", " ", m.group(0)), text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    tokens = [(m.group(0), text.count("\n", 0, m.start()) + 1)
              for m in re.finditer(r'"[^"\n]*"|[{}]|[^\s{}"]+', text)]
    top, stack, statement = [], [], []
    for token, line in tokens:
        if token == "{":
            words = [w.strip('"') for w, _ in statement]
            abstract = bool(words) and words[0] == "abstract"
            words = words[1:] if abstract else words
            if not words:
                raise ValueError("line %d: `{` without an object header" % line)
            bases = words[words.index(":") + 1:] if ":" in words else []
            head = words[:words.index(":")] if ":" in words else words
            obj = ScriptObject(head[0], head[1] if len(head) > 1 else "", bases, abstract,
                               statement[0][1])
            (stack[-1].children if stack else top).append(obj)
            stack.append(obj)
            statement = []
        elif token == "}":
            if not stack:
                raise ValueError("line %d: unmatched `}`" % line)
            stack.pop()
            statement = []
        else:
            if statement and statement[-1][1] != line:
                statement = []  # the previous line was a property
            statement.append((token, line))
    if stack:
        raise ValueError("line %d: object %s %s not closed" % (stack[-1].line, stack[-1].cls, stack[-1].name))
    return top


def overlay(source, dest):
    """OGRE's ScriptCompiler::overlayObject: the base `source`'s objects into `dest`."""
    overrides = [[child, None] for child in source.children]
    indices, overridden, highest = {}, set(), 0
    for node in dest.children:  # pair named objects by class and name
        indices[id(node)] = highest
        for j, pair in enumerate(overrides):
            if node.name and pair[0].cls == node.cls and pair[0].name == node.name:
                if pair[1] is None:
                    pair[1] = node
                    highest = max(j, highest)
                    indices[id(node)] = highest
                    overridden.add(id(node))
                break
    for node in dest.children:  # then unnamed ones by class, in order
        if id(node) not in overridden:
            for pair in overrides[indices[id(node)]:]:
                if not pair[0].name and pair[0].cls == node.cls and pair[1] is None:
                    pair[1] = node
                    break
    at = 0
    for base, node in overrides:
        if node is not None:
            overlay(base, node)
            at = next(i for i, c in enumerate(dest.children) if c is node) + 1
        else:
            dest.children.insert(at, base.clone())
            at += 1


def resolve_bases(objects, top, script):
    """OGRE's ScriptCompiler::processObjects: each object's bases overlaid in order, then its children's."""
    for obj in objects:
        for base in obj.bases:
            found = [o for o in top if o.name == base]
            if not found:
                raise ValueError("%s:%d: %s %s: base %s not found in this script"
                                 % (script, obj.line, obj.cls, obj.name, base))
            overlay(found[-1], obj)
        resolve_bases(obj.children, top, script)


def material_passes(materials):
    """(script, line, material, technique, pass, vertex program, fragment program) of every pass
    of the non-abstract materials of MATERIALS_DIR/*.material; a program is None if not set."""
    found = []
    for script in sorted(f for f in os.listdir(materials) if f.endswith(".material")):
        top = script_objects(open(os.path.join(materials, script)).read())
        resolve_bases(top, top, script)
        for material in top:
            if material.cls != "material" or material.abstract:
                continue
            techniques = [c for c in material.children if c.cls == "technique"]
            for t, technique in enumerate(techniques):
                passes = [c for c in technique.children if c.cls == "pass"]
                for n, pass_ in enumerate(passes):
                    def program(cls):
                        refs = [c.name for c in pass_.children if c.cls == cls]
                        return refs[-1] if refs else None
                    found.append((script, pass_.line, material.name, technique.name or str(t),
                                  pass_.name or str(n), program("vertex_program_ref"),
                                  program("fragment_program_ref")))
    return found


# Pixel-shader inputs the rasteriser makes, not the vertex program.
RASTERISER_VALUES = {"SV_POSITION0", "SV_ISFRONTFACE0", "SV_SAMPLEINDEX0", "SV_PRIMITIVEID0", "SV_COVERAGE0"}
INTERPOLATION = {"nointerpolation", "linear", "centroid", "noperspective", "sample"}


def declared_at(resolved, macro, name):
    """FILE:LINE of the IN/OUT/FLAT_IN/FLAT_OUT (`macro`) declaring `name` in a source with its
    includes resolved (resolve_includes' #line directives), or "" unless there is exactly one.
    (glslang's -E output does not keep line numbers across a skipped #include.)"""
    hits, file, number = [], "?", 1
    for text in resolved.split("\n"):
        m = re.match(r'\s*#line\s+(\d+)\s+"([^"]*)"', text)
        if m:
            number, file = int(m.group(1)), m.group(2)
            continue
        if re.search(r"\b(?:FLAT_)?%s\(\s*\w+\s+%s\s*(?:\[[^]]*\]\s*)?," % (macro, re.escape(name)), text):
            hits.append("%s:%d" % (file, number))
        number += 1
    return hits[0] if len(hits) == 1 else ""


def stage_interface(preprocessed, entry, resolved):
    """main's parameters in `glslangValidator -E` output: a list of dicts with direction,
    interpolation, type, name, semantic (upper case, with its index), where (FILE:LINE or "")."""
    text = "\n".join(line for line in preprocessed.split("\n") if not line.lstrip().startswith("#"))
    m = re.search(r"\b\w+\s+%s\s*\(" % re.escape(entry), text)
    if not m:
        raise ValueError("no function %s in the preprocessed source" % entry)
    parameters = []
    for chunk in text[m.end():text.index(")", m.end())].split(","):
        declaration, _, semantic = chunk.partition(":")
        words = declaration.split()
        if not words or "uniform" in words:
            continue
        declaration = re.sub(r"\s*\[", "[", " ".join(words))  # `float2 v [2]` as `float2 v[2]`
        words = declaration.split()
        name, array = re.match(r"(\w+)(.*)", words[-1]).groups()
        semantic = semantic.strip().upper()
        parameters.append({"direction": next((w for w in words if w in ("in", "out", "inout")), "in"),
                           "interpolation": " ".join(w for w in words if w in INTERPOLATION),
                           "type": words[-2] + array, "name": name,
                           # Direct3D's semantic: a name and an index, TEXCOORD meaning TEXCOORD0.
                           "semantic": semantic if not semantic or re.search(r"\d$", semantic) else semantic + "0"})
        parameters[-1]["where"] = declared_at(resolved, "OUT" if parameters[-1]["direction"] == "out" else "IN", name)
    return parameters


def describe(parameter):
    if parameter is None:
        return "none"
    return "%s %s%s %s%s" % (parameter["semantic"], parameter["interpolation"] + " " if parameter["interpolation"] else "",
                             parameter["type"], parameter["name"], ", " + parameter["where"] if parameter["where"] else "")


def main():
    materials, folders, validator = command_line(__doc__)
    found, units, delegates = [], {}, {}
    for script in sorted(f for f in os.listdir(materials) if f.endswith(".program")):
        text = open(os.path.join(materials, script)).read()
        for kind, name, language, body, line in blocks(text, ("hlsl", "unified")):
            if language == "unified":
                # The texture units of the unified program's samplers, for each HLSL delegate.
                params = dict(re.findall(r"^\s*param_named\s+(\w+)\s+int\s+(\d+)", body, re.M))
                delegates[name] = re.findall(r"^\s*delegate\s+(\S+)", body, re.M)
                for delegate in delegates[name]:
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
    preprocessed = {}  # for link()
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
        text = resolve_includes(path, folders, line_markers=True)
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
            # For link(); a vertex program whose defines have INSTANCED is its own Forest variant.
            preprocessed[(name, variant != defines)] = (pre.stdout, entry, text)
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
    mismatches = link(materials, found, delegates, preprocessed)
    return 1 if failures or mismatches else 0


def link(materials, found, delegates, preprocessed):
    """The linkage check (module docstring); prints each mismatch and a summary, returns the mismatches.
    `preprocessed` maps (hlsl program, the Forest's INSTANCED variant?) to (-E output, entry point,
    source with includes resolved)."""
    kinds = {name: kind for _, _, kind, name, *_ in found}
    key = lambda p: p and (p["semantic"], p["type"], p["interpolation"])  # what must match

    def hlsl(name, kind):
        """The hlsl program a material's program name stands for, or an error."""
        candidates = [d for d in delegates.get(name, [name]) if d in kinds]
        if not candidates:
            return None, "%s program %s has no hlsl program or delegate" % (kind, name)
        if kinds[candidates[0]] != kind:
            return None, "%s program %s is a %s program" % (kind, name, kinds[candidates[0]])
        return candidates[0], None

    passes, linkages, skipped, mismatches = 0, 0, 0, []
    try:
        found_passes = material_passes(materials)
    except ValueError as e:
        print("FAIL reading the materials: %s" % e)
        return [str(e)]
    for script, line, material, technique, pass_, vertex, fragment in found_passes:
        where = "%s:%d: material %s technique %s pass %s" % (script, line, material, technique, pass_)
        if not vertex or not fragment:
            skipped += 1
            continue
        passes += 1
        vs, error = hlsl(vertex, "vertex")
        fs, error2 = hlsl(fragment, "fragment")
        if error or error2:
            mismatches += ["%s: %s" % (where, e) for e in (error, error2) if e]
            continue
        if (fs, False) not in preprocessed:
            continue  # did not compile: reported above
        inputs = [p for p in stage_interface(*preprocessed[(fs, False)]) if p["direction"] == "in"
                  and p["semantic"] not in RASTERISER_VALUES]
        for instanced in (False, True):
            label = vertex + ("/Instanced" if instanced else "")
            if (vs, instanced) not in preprocessed:
                continue
            linkages += 1
            outputs = [p for p in stage_interface(*preprocessed[(vs, instanced)]) if p["direction"] == "out"
                       and p["semantic"] != "SV_POSITION0"]
            for n in range(max(len(outputs), len(inputs))):
                o = outputs[n] if n < len(outputs) else None
                i = inputs[n] if n < len(inputs) else None
                if key(o) != key(i):
                    mismatches.append("%s: vertex %s output %d (%s) vs fragment %s input %d (%s)"
                                      % (where, label, n, describe(o), fragment, n, describe(i)))
    for m in mismatches:
        print("FAIL " + m)
    print("%d passes linked (%d linkages: vertex programs as declared and as INSTANCED=1), %d passes "
          "with one program only, %d mismatches" % (passes, linkages, skipped, len(mismatches)))
    return mismatches


if __name__ == "__main__":
    sys.exit(main())
