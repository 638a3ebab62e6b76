// libFuzzer harness for the OpenSCAD .csg import: any input must translate or throw
// voxfield::Error, with ideal shapes and with facets; a translation must parse as the model
// language (the importer writes only valid text) and evaluate.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "fuzz_common.h"
#include "voxfield/csg.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  voxfield::fuzz::init_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace voxfield::csg;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (bool facets : {false, true}) {
    OpenScadOptions o;
    o.facets = facets;
    std::string translated;
    try {
      translated = translate_openscad_csg(text, "fuzz.csg", o);
    } catch (const voxfield::Error&) {
      continue;
    }
    try {
      const Model m = parse_model_sexpr(translated, "translated");
      if (model_info(m).nodes <= 5000) (void)evaluate(m, {0.5, 0.25, 0.125});
    } catch (const ModelError& e) {
      // Numbers past the language's range are refused by it; anything else is an importer bug.
      if (std::string_view(e.what()).find("larger than 1e12") == std::string_view::npos &&
          std::string_view(e.what()).find("out of range") == std::string_view::npos &&
          std::string_view(e.what()).find("2^20 nodes") == std::string_view::npos)
        std::abort();
    }
  }
  return 0;
}
