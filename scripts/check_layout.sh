#!/usr/bin/env bash
# The layout rules (docs/architecture.md, "Layout rules"), run by ctest as
# CpuLayout.TechniqueFactsStayInTheirFolders. A technique's *facts* live in its folder,
# techniques/<id>/: its sources, shaders, page, parameter table, pass and shader names, paper
# values, configs, tables script and tests. Mentions elsewhere (a comment, a doc that compares
# techniques, a cross-technique config or test, the registry's table line) are fine.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
exec python3 - "$@" <<'PY'
import json, os, re, subprocess, sys

errors = []
def err(msg): errors.append(msg)

table = re.findall(r'^gilab_add_technique\(([a-z0-9_]+)', open('CMakeLists.txt').read(), re.M)
if not table: sys.exit('no gilab_add_technique lines in CMakeLists.txt')
ids = set(table)
folders = {d for d in os.listdir('techniques') if os.path.isdir(os.path.join('techniques', d))}
for t in sorted(ids - folders): err(f"technique table names '{t}' but techniques/{t}/ does not exist")
for t in sorted(folders - ids): err(f"techniques/{t}/ is not in the technique table of CMakeLists.txt")

files = subprocess.run(['git', 'ls-files', '--cached', '--others', '--exclude-standard'],
                       capture_output=True, text=True, check=True).stdout.split('\n')
files = [f for f in files if f and os.path.isfile(f) and not f.startswith('results/')]
def owner(f):
    # A technique folder: techniques/<id>/, or the tutorial's example folder docs/tutorial/<id>/.
    parts = f.split('/')
    if parts[0] == 'techniques' and len(parts) > 2: return parts[1]
    if parts[:2] == ['docs', 'tutorial'] and len(parts) > 3: return parts[2]
    return None

# 1. Shaders: shaders/ holds only the shared ones (shaders/common/).
for f in files:
    if f.startswith('shaders/') and not f.startswith('shaders/common/'):
        err(f"{f}: a technique's shader belongs in techniques/<id>/shaders/ (shaders/ is shared)")

# 2. A technique's page, tables script, config or test (named after it) outside its folder.
allowed_named = {
    # The tutorial's sweep of vct (docs/tutorial.md, section 4): a docs config, not vct's own.
    'experiments/configs/tutorial_sweep.json',
}
for f in files:
    if owner(f) or f in allowed_named: continue
    base = os.path.basename(f)
    kind = (base.endswith(('.md', '.json', '_tables.py', '_table.py')) or
            re.search(r'_test(_[a-z]+)?\.(cpp|h)$', base))
    for t in ids:
        if (kind and re.match(rf'^{t}([._]|$)', base)) or f'/{t}/' in f'/{os.path.dirname(f)}/':
            if f.startswith('techniques/') or f.startswith('docs/tutorial/'): continue
            err(f"{f}: named after technique '{t}'; it belongs in techniques/{t}/")

# 3. Sources: only a technique's folder includes its headers (cross-technique tests may), and a
#    technique includes only core/ and itself.
inc = re.compile(r'#include\s+"([^"]+)"')
for f in files:
    if not f.endswith(('.h', '.cpp')): continue
    o = owner(f)
    for m in inc.finditer(open(f, encoding='utf-8', errors='replace').read()):
        path = m.group(1)
        tm = re.match(r'techniques/([a-z0-9_]+)/', path)
        if tm and tm.group(1) != o and not f.startswith('tests/'):
            err(f"{f}: includes {path}, a source of technique '{tm.group(1)}'")
        in_tests = '/tests/' in f
        if o and not in_tests and '/' in path and not (
                path.startswith('core/') or path.startswith(f'techniques/{o}/')):
            err(f"{f}: technique '{o}' includes {path} (a technique builds on core/ only)")

# 4. Parameter tables: declared by a technique in its folder, by core/ for the shared passes,
#    or by the path-tracer baseline; tests may build their own.
param = re.compile(r'\b(float|int|bool|enum|string)Param\(')
allowed_params = ('core/', 'tests/', 'docs/tutorial/', 'experiments/runner/pt_baseline.cpp')
for f in files:
    if not f.endswith(('.h', '.cpp')) or owner(f) or f.startswith(allowed_params): continue
    if param.search(open(f, encoding='utf-8', errors='replace').read()):
        err(f"{f}: declares a parameter table outside a technique folder")

# 5. Shader and pass names ("<id>/..." string literals) outside the technique's folder, in code
#    (comments are mentions).
for f in files:
    if not f.endswith(('.h', '.cpp', '.py', '.glsl', '.comp', '.frag', '.vert', '.geom')): continue
    if owner(f) or f.startswith('tests/'): continue
    for n, line in enumerate(open(f, encoding='utf-8', errors='replace'), 1):
        code = line.split('//')[0] if not f.endswith('.py') else line.split('#')[0]
        if code.lstrip().startswith('*'): continue
        for t in ids:
            if re.search(rf'"{t}/[A-Za-z0-9_.]+', code):
                err(f"{f}:{n}: names a pass or shader of '{t}' outside techniques/{t}/")

# 6. Paper facts: paper.json lives in a technique folder.
for f in files:
    if os.path.basename(f) == 'paper.json' and not owner(f) and not f.startswith('docs/tutorial/'):
        err(f"{f}: paper facts belong in techniques/<id>/paper.json")

# 7. Layering: core/'s layers include only their own or lower ones; core/ names no technique and
#    includes nothing outside core/; the runner never includes the command line.
rank = {'util': 0, 'scene': 1, 'image': 1, 'params': 1, 'vk': 2, 'gpu': 2, 'rt': 3, 'passes': 3, 'voxel': 3,
        'vpl': 4, 'technique': 5}
for f in files:
    if not f.endswith(('.h', '.cpp')): continue
    text = open(f, encoding='utf-8', errors='replace').read()
    if f.startswith('core/'):
        layer = f.split('/')[1]
        for m in inc.finditer(text):
            p = m.group(1)
            if '/' not in p: continue
            if not p.startswith('core/'):
                err(f"{f}: core/ includes {p}")
            elif rank.get(p.split('/')[1], 99) > rank.get(layer, -1):
                err(f"{f}: layer core/{layer} includes {p}, a higher layer")
        for t in ids:
            if re.search(rf'techniques/{t}\b|"{t}/', text):
                err(f"{f}: core/ names technique '{t}'")
    if f.startswith('experiments/runner/') and 'experiments/cli/' in text:
        err(f"{f}: the runner includes the command line (experiments/cli/)")
    if f.startswith('reference/') and re.search(r'#include "(experiments|techniques)/', text):
        err(f"{f}: reference/ includes experiments/ or techniques/")

for e in errors: print(e)
if errors: sys.exit(1)
print(f"layout ok: {len(ids)} technique(s), each one folder; core/ names none; layers hold")
PY
