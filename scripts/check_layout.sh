#!/usr/bin/env bash
# Checks the plugin layout rules (docs/architecture.md): core/ never names a technique, and each
# technique in the CMake table has its folder. Run by ctest as CpuLayout.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
status=0
ids=$(sed -n 's/^gilab_add_technique(\([a-z0-9_]*\).*/\1/p' CMakeLists.txt)
[ -n "$ids" ] || { echo "no gilab_add_technique lines in CMakeLists.txt"; exit 1; }
for id in $ids; do
    if [ ! -d "techniques/$id" ]; then
        echo "technique table names '$id' but techniques/$id/ does not exist"; status=1
    fi
    if grep -rn --include='*.h' --include='*.cpp' --include='*.glsl' --include='*.comp' \
        -e "techniques/$id" -e "\"$id/" -e "shaders/$id/" core shaders/common; then
        echo "core/ or shaders/common names technique '$id' (core must stay technique-agnostic)"
        status=1
    fi
done
[ $status -eq 0 ] && echo "layout ok: $(echo $ids | wc -w) technique(s), core/ names none"
exit $status
