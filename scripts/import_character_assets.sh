#!/usr/bin/env bash
# Imports the motion-capture clip shipped in assets/characters/ from Debian's package
# assimp-testmodels (BSD-3-clause outside models-nonbsd/, see its copyright file; the BVH clips
# are the cgspeed.com conversion of the CMU Graphics Lab Motion Capture Database, which
# places no restriction on use, see 01_nn.bvh.source.txt).
#
# Writes:
#   assets/characters/cmu_01_01_4s.bvh              01_01.bvh ("playground: forward jumps"),
#                                                   trimmed to FRAMES frames from START, every
#                                                   STRIDE-th source frame kept
#   assets/characters/LICENSE-assimp-testmodels.txt the package's copyright file, verbatim
#   assets/characters/CMU-mocap-README.txt          the .source.txt beside the BVH files
#   assets/characters/simple_skin.gltf              models/glTF2/simple_skin (2 joints, 10
#                                                   vertices, a bending animation; BSD-3)
#   assets/characters/bcn_epileptic.glb             models/X/BCN_Epileptic.X (a skinned human in
#                                                   three meshes on one 54-joint skin, a 3.3 s
#                                                   jump; BSD-3) converted to GLB by
#                                                   `assimp export`
#
# Needs: apt-get (or DEB=…), dpkg, awk, and `assimp` from Debian's assimp-utils
# (`apt-get install -y assimp-utils`) for the GLB conversion.
#
# Usage: scripts/import_character_assets.sh   (env: DEB=path/to/assimp-testmodels_*.deb to use
#        a downloaded package; START=120 FRAMES=240 STRIDE=2, i.e. 1 s to 5 s at 60 fps)
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
out="$repo/assets/characters"
START="${START:-120}"
FRAMES="${FRAMES:-240}"
STRIDE="${STRIDE:-2}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

if [ -z "${DEB:-}" ]; then
  (cd "$work" && apt-get download assimp-testmodels)
  DEB="$(ls "$work"/assimp-testmodels_*_all.deb)"
fi
echo "# extracting $DEB" >&2
dpkg -x "$DEB" "$work/x"
models="$work/x/usr/share/assimp/models"
mkdir -p "$out"
cp "$work/x/usr/share/doc/assimp-testmodels/copyright" "$out/LICENSE-assimp-testmodels.txt"
cp "$models/BVH/01_nn.bvh.source.txt" "$out/CMU-mocap-README.txt"
cp "$models/glTF2/simple_skin/simple_skin.gltf" "$out/simple_skin.gltf"

# The skinned human: DirectX .X to binary glTF. Already y-up and in metres (feet at
# y = -1.02 m): scenes place it with [character] position, not by editing the data.
if ! command -v assimp >/dev/null; then
  echo "assimp not found: apt-get install -y assimp-utils" >&2; exit 1
fi
(cd "$work" && assimp export "$models/X/BCN_Epileptic.X" bcn_epileptic.glb >/dev/null)
cp "$work/bcn_epileptic.glb" "$out/bcn_epileptic.glb"
echo "# wrote $out/bcn_epileptic.glb" >&2

# Hierarchy verbatim; MOTION header rewritten for the kept frames; frames START,
# START + STRIDE, … (0-based), FRAMES of them. Fails if the source has too few frames.
awk -v start="$START" -v count="$FRAMES" -v stride="$STRIDE" '
  BEGIN { motion = 0; frame = -1; kept = 0 }
  { sub(/\r$/, "") }
  motion == 0 { print; if ($1 == "MOTION") motion = 1; next }
  $1 == "Frames:" { total = $2; next }
  $1 == "Frame" && $2 == "Time:" {
    if (start + (count - 1) * stride >= total) {
      print "source has " total " frames, too few for the trim" > "/dev/stderr"; exit 1
    }
    print "Frames: " count
    printf "Frame Time: %.7f\n", $3 * stride
    next
  }
  NF > 0 {
    frame++
    if (frame >= start && (frame - start) % stride == 0 && kept < count) { print; kept++ }
  }
  END { if (kept != count) { print "kept " kept " of " count " frames" > "/dev/stderr"; exit 1 } }
' "$models/BVH/01_01.bvh" > "$out/cmu_01_01_4s.bvh"
echo "# wrote $out/cmu_01_01_4s.bvh ($FRAMES frames)" >&2
