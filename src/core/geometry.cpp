// The contact-resolution kernels are inline in geometry.hpp so the force loop can inline them.
#include "core/geometry.hpp"
