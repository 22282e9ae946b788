#!/usr/bin/env bash
# Compiles benchmarks/pinocchio_native.cpp against the `pin` wheel in .venv (headers and libraries
# under its cmeel.prefix; Eigen from the cmeel-eigen wheel) with -O3 -DNDEBUG and no -march flag,
# the same target as robodyn's release build, and prints Pinocchio's native ns per call.
set -euo pipefail
cd "$(dirname "$0")/.."
.venv/bin/python -m pip install --quiet "pin" "cmeel-eigen" "cmeel-urdfdom-headers" "example-robot-data"
prefix=$(.venv/bin/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')/cmeel.prefix
robots="$prefix/share/example-robot-data/robots"
mkdir -p target/pinocchio-native
binary=target/pinocchio-native/bench
# the compile definitions of the wheel's pinocchio CMake targets
g++ -O3 -DNDEBUG -std=c++17 -w -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 \
    -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_FUSION_INVOKE_MAX_ARITY=12 \
    -DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION -DPINOCCHIO_WITH_URDFDOM -DPINOCCHIO_URDFDOM_HEADERS_MAJOR_VERSION=3 \
    benchmarks/pinocchio_native.cpp -o "$binary" \
    -I"$prefix/include" -I"$prefix/include/eigen3" -I"$prefix/include/urdfdom_headers" -I"$prefix/include/urdfdom" -L"$prefix/lib" -Wl,-rpath,"$prefix/lib" \
    -lpinocchio_default -lpinocchio_parsers -lboost_filesystem
"$binary" \
    ur5 "$robots/ur_description/urdf/ur5_robot.urdf" 0 tool0 \
    panda "$robots/panda_description/urdf/panda.urdf" 0 panda_hand_tcp \
    talos "$robots/talos_data/robots/talos_full_v2.urdf" 1 gripper_left_fingertip_1_link
