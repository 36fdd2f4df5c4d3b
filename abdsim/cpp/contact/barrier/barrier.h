// IPC log barrier on the squared distance x = d², with a thickness offset ξ (the sum of both
// primitives' thickness radii, 0 for solids), exactly as ABD_NOTES §7:
//     b(x) = −(x − X)² log((x − Y)/(X − Y)),   X = (d̂ + ξ)²,  Y = ξ²,
// active only for Y < x < X; times the contact stiffness κ_c by the caller. b, b' and b''
// all vanish at x = X (C² activation). With ξ = 0 this is IPC's barrier on squared distances:
// b(d²; d̂, 0) = ipctk.barrier(d², d̂²), and in general b(x; d̂, ξ) = ipctk.barrier(x − ξ², X − Y).
// Derivatives are w.r.t. x = d² (not d). At or inside the thickness (x <= Y) the barrier is
// infinite: value +inf, first derivative −inf, second derivative +inf.
#pragma once

namespace abd::contact {

double barrier(double d2, double d_hat, double xi = 0.0);
double barrier_first_derivative(double d2, double d_hat, double xi = 0.0);
double barrier_second_derivative(double d2, double d_hat, double xi = 0.0);

// Contact force magnitude λ = −∂(κ b)/∂d = −2 d κ b'(d²): IPC's lagged normal force for
// friction (d the unsigned distance).
double barrier_force_magnitude(double d2, double d_hat, double xi, double kappa);

}  // namespace abd::contact
