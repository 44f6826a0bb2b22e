# bench/device/setup.sh: sourced on the GPU machine in the repository root (see pack.sh). Unpacks
# the carried libraries, points the ICD loader at NVIDIA's OpenCL driver and puts the binaries
# where the tests expect them (the checkout there is /work/main, as here).
R=$PWD
mkdir -p /tmp/devlib && tar -xJf .devrun/lib.tar.xz -C /tmp/devlib
NV=$(dirname "$(ls /usr/local/nvidia/lib64/libnvidia-opencl.so.1 /usr/lib/x86_64-linux-gnu/libnvidia-opencl.so.1 2>/dev/null | head -1)")
export LD_LIBRARY_PATH=/tmp/devlib/lib:$NV:${LD_LIBRARY_PATH:-}
export OCL_ICD_VENDORS=$R/.devrun/icd NARVAL_CACHE_DIR=/tmp/narval-cache NARVAL_DATA_DIR=$R/.devrun/data
mkdir -p build/tests scenes/data /work/shared/data
ln -sfn "$R/.devrun/bin/narval" build/narval
for t in render device cli; do ln -sfn "$R/.devrun/bin/narval_${t}_tests" "build/tests/narval_${t}_tests"; done
[ -e /work/shared/data/volumes ] || ln -sfn "$R/.devrun/data" /work/shared/data/volumes
[ -f scenes/data/cloud_128.vdb ] || build/narval make-cloud scenes/data/cloud_128.vdb --resolution 128 >/dev/null
