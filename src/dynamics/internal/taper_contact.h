#pragma once

// Contact stiffness of a tool holder's taper in the spindle (the seed's
// spindle–toolholder interface model), condensed onto the gauge line.
//
// 1. Pressure. The drawbar force F pulls the holder into the cone of
//    half-angle α (tan α = taper_ratio / 2). With a uniform normal pressure p
//    on the contact area A and Coulomb friction μ p opposing the draw-in, the
//    axial equilibrium F = p A (sin α + μ cos α) gives p [seed §1.2]. A is
//    the lateral area of the frustum, π (R₁ + R₂) L / cos α.
// 2. Unit-area stiffness (Yoshimura's law): k_n = α' p^β' normal and
//    k_t = (tangential_to_normal) k_n tangential, both per unit area
//    [Yoshimura 1979]. Units: with p in Pa, k_n is in N/m per m² (N/m³);
//    the seed's α' = 3262540, β' = 0.604 then give k_n ≈ 8.8e10 N/m³ at
//    21 MPa and a lateral interface stiffness ≈ 8e7 N/m for HSK-E32, the
//    order the seed reports (1e8 N/m).
// 3. Elements. The taper is cut into N rings of axial length h = L/N. Ring i
//    (mid depth z_i below the gauge line, mid radius r_i, area
//    A_i = 2π r_i h / cos α) moved by a section translation w and rotation θ
//    in the x–z plane has springs k_n along the cone normal
//    n = (cos α cos φ, cos α sin φ, −sin α) and k_t along the generatrix and
//    the circumference. Integrating ½ Σ k (dir·d)² over φ ∈ [0, 2π) gives
//      k_ww = A_i/2 (k_n cos²α + k_t sin²α + k_t)
//      k_wθ = A_i/2 r_i sin α cos α (k_n − k_t)                          (3)
//      k_θθ = A_i/2 r_i² (k_n sin²α + k_t cos²α)
//    (the tilt moves the ring's points axially by ∓θ r cos φ).
// 4. Shank and condensation. The ring nodes sit on the holder's hollow taper
//    shank, an Euler–Bernoulli beam (outer diameter of the taper, bore
//    shank_bore_diameter) from the gauge line (node 0) through the ring
//    nodes. The assembled 2(N+1) stiffness is condensed onto node 0 by
//    Guyan's static condensation K_c = K_mm − K_ms K_ss⁻¹ K_sm [Guyan 1965].
//    A rigid shank (modulus = +inf) replaces the beam by rigid links:
//    K_c = Σ T_iᵀ k_i T_i with T_i = [1 −z_i; 0 1] (w = u − z θ).
// 5. Both planes. In the x–z plane the master DOFs are (u_x, θ_y); in the
//    y–z plane a positive θ_x moves a section at depth z by +z in y, so the
//    y–z matrix is the x–z one with θ → −θ_x.
//
// - [Guyan 1965] R. J. Guyan, Reduction of stiffness and mass matrices,
//   AIAA Journal 3(2):380, 1965.
// - [Yoshimura 1979] M. Yoshimura, Computer-aided design improvement of
//   machine tool structure incorporating joint dynamics data, Annals of the
//   CIRP 28(1):241–246, 1979.
// - [seed] robot milling tool-tip FRF prediction considering the
//   spindle–toolholder interface contact stiffness, §1.2.
#include <Eigen/Core>

namespace robomach::dynamics::internal {

struct TaperContactOptions {
  int elements{6};
  double friction_coefficient{0.15};
  double alpha_prime{3262540.0};        // k_n = alpha' p^beta' [N/m³, p in Pa]
  double beta_prime{0.604};
  double tangential_to_normal{0.5};
  double drawbar_force_N{5000.0};
  double large_diameter_m{0.024007};    // at the gauge line
  double length_m{0.016};
  double taper_ratio{0.1};              // diameter change per length
  double shank_bore_diameter_m{0.016};
  double shank_modulus_Pa{2.1e11};      // +inf: rigid shank
};

struct TaperContact {
  double half_angle_rad{0.0};
  double contact_area_m2{0.0};
  double pressure_Pa{0.0};
  double normal_stiffness_N_per_m3{0.0};
  double tangential_stiffness_N_per_m3{0.0};
  /// Node depths below the gauge line [m]: 0 (master), then the ring mid-planes.
  Eigen::VectorXd node_depth_m;
  /// Assembled stiffness of one plane before condensation, DOFs (w_j, θ_j)
  /// per node j (elastic shank only; empty for a rigid one).
  Eigen::MatrixXd K_full;
  /// Condensed onto the gauge line in the x–z plane, DOFs (u_x, θ_y).
  Eigen::Matrix2d K_plane{Eigen::Matrix2d::Zero()};
  /// Both planes, DOFs [u_x, u_y, θ_x, θ_y] [N/m, N/rad, N·m/rad].
  Eigen::Matrix4d K_master{Eigen::Matrix4d::Zero()};
};

/// @throws std::invalid_argument naming the offending option.
TaperContact ComputeTaperContact(const TaperContactOptions& options);

/// Ring element (3) as a 2×2 matrix on (w, θ).
Eigen::Matrix2d RingStiffness(double area_m2, double radius_m, double half_angle_rad, double k_n,
                              double k_t);

/// Both planes from the x–z plane (item 5), DOFs [u_x, u_y, θ_x, θ_y].
Eigen::Matrix4d BothPlanes(const Eigen::Matrix2d& K_xz);

}  // namespace robomach::dynamics::internal
