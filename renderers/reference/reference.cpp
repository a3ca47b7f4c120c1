// The reference method: the quadrature truth by default, the Monte Carlo integrator on request (reference.h).
#include "renderers/reference/reference.h"

#include "renderers/option_table.h"

namespace iblcheck {

bool uses_quadrature(const TestSpec& spec) {
    return option_choice(spec.options, "integrator") == "quadrature"; // the table: monte_carlo once spp is set
}

RenderResult render_reference(const TestSpec& spec) {
    if (uses_quadrature(spec)) return truth::render_truth(spec, load_environment(spec.env)).result;
    return render_reference_full(spec).result;
}
RenderResult render_reference(const TestSpec& spec, const Environment& env) {
    if (uses_quadrature(spec)) return truth::render_truth(spec, env).result;
    return render_reference_full(spec, &env).result;
}

} // namespace iblcheck
