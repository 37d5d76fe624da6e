// The solve of one refinement window (refinement_window.h): every residual family
// (photometric_residuals.h, regularization_residuals.h) over the window's frames and
// active patches and vertices, NCC blocks under a Cauchy loss (ncc_loss_scale), the
// increments bounded, solved by Ceres (WindowSolverOptions). The window's increments are
// the solver's parameter storage; the shapes it was opened on are not touched: the
// solution says how to move each vertex of each frame.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"
#include "solver/stereo/refinement_window.h"
#include "vision/working_volume.h"

namespace subflow::solver {

struct WindowFrameFigures {
  int frame = 0;
  int stereo_pairs = 0;  // camera pairs with a stereo residual (0: the frame was not refined)
  // Mean NCC over those pairs (ε-regularized) and RMS one-sided silhouette distance
  // (pixels), before and after the solve.
  double ncc_before = 0, ncc_after = 0;
  double silhouette_rms_before = 0, silhouette_rms_after = 0;
};

struct WindowSolution {
  int first = 0, last = 0;  // the frames solved
  using Increments = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  // Per frame first..last: the increments e (#V(ℓ) × dof, in the vertices' bases) and the
  // same as world displacements B e (#V(ℓ) × 3). Zero for inactive vertices.
  std::vector<Increments> increments;
  std::vector<geometry::Positions> displacement;
  std::vector<WindowFrameFigures> frames;  // per frame first..last
  int parameters = 0;       // free scalar unknowns
  int vertex_blocks = 0;    // free increment blocks (vertex × frame): what chooses the solver
  int residual_blocks = 0;
  int iterations = 0;       // Ceres iterations
  // Solved by options.solver.iterative_solver (else by linear_solver, or not at all: a
  // window without unknowns or residuals is not solved).
  bool iterative = false;
  double solver_seconds = 0;  // inside ceres::Solve
};

WindowSolution SolveWindow(RefinementWindow& window, const vision::Bounds& bounds);

}  // namespace subflow::solver
