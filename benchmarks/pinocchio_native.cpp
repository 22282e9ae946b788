// Native timing of Pinocchio's C++ algorithms, to set robodyn's criterion figures beside.
// Built and run by benchmarks/pinocchio_native.sh against the headers and libraries of the `pin`
// wheel. Prints nanoseconds per call (best of 5 rounds) for each robot given on the command line
// as `name path floating(0|1) frame`; the Jacobian is that frame's.
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

template <typename F> double best_ns(F&& call, int calls) {
  double best = 1e300;
  for (int round = 0; round < 5; ++round) {
    auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < calls; ++k) call();
    std::chrono::duration<double, std::nano> elapsed = std::chrono::steady_clock::now() - start;
    best = std::min(best, elapsed.count() / calls);
  }
  return best;
}

int main(int argc, char** argv) {
  for (int arg = 1; arg + 3 < argc; arg += 4) {
    const std::string name = argv[arg];
    pinocchio::Model model;
    if (std::atoi(argv[arg + 2]))
      pinocchio::urdf::buildModel(argv[arg + 1], pinocchio::JointModelFreeFlyer(), model);
    else
      pinocchio::urdf::buildModel(argv[arg + 1], model);
    pinocchio::Data data(model);
    model.lowerPositionLimit.head<3>().fill(-1.0);  // finite bounds for a free flyer
    model.upperPositionLimit.head<3>().fill(1.0);
    Eigen::VectorXd q = pinocchio::randomConfiguration(model);
    Eigen::VectorXd v = Eigen::VectorXd::Constant(model.nv, 0.5);
    Eigen::VectorXd a = Eigen::VectorXd::Constant(model.nv, 0.25);
    const auto frame = model.getFrameId(argv[arg + 3]);
    pinocchio::Data::Matrix6x jacobian = pinocchio::Data::Matrix6x::Zero(6, model.nv);
    const int calls = 20000;
    std::printf("%s forward_kinematics %.1f\n", name.c_str(),
                best_ns([&] { pinocchio::forwardKinematics(model, data, q); }, calls));
    std::printf("%s jacobian %.1f\n", name.c_str(), best_ns([&] {
      pinocchio::computeFrameJacobian(model, data, q, frame, pinocchio::LOCAL_WORLD_ALIGNED, jacobian);
    }, calls));
    std::printf("%s rnea %.1f\n", name.c_str(), best_ns([&] { pinocchio::rnea(model, data, q, v, a); }, calls));
    std::printf("%s gravity %.1f\n", name.c_str(),
                best_ns([&] { pinocchio::computeGeneralizedGravity(model, data, q); }, calls));
    std::printf("%s crba %.1f\n", name.c_str(), best_ns([&] { pinocchio::crba(model, data, q); }, calls));
    std::printf("%s aba %.1f\n", name.c_str(), best_ns([&] { pinocchio::aba(model, data, q, v, a); }, calls));
    std::printf("%s rnea_derivatives %.1f\n", name.c_str(),
                best_ns([&] { pinocchio::computeRNEADerivatives(model, data, q, v, a); }, calls / 4));
    std::printf("%s aba_derivatives %.1f\n", name.c_str(),
                best_ns([&] { pinocchio::computeABADerivatives(model, data, q, v, a); }, calls / 4));
  }
  return 0;
}
