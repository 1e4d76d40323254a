// libFuzzer target: the model file (TOML) reader, io::read_model, with its [modal], [matrices],
// [frf] and [[substructures]] tables. Contract: a result or io::Error; anything else escaping is a
// finding. Beside the input lie the files a model may reference (copied at start): portal.msh (the
// portal frame's mesh), k.mtx, m.mtx, dofs.txt (the cantilever's matrices) and h.csv (a
// mobility table of fuzz/corpus/fuzz_frf_csv), and frf_part.toml, modal_part.toml and
// matrices_part.toml (the [frf], [modal] and [matrices] seeds, parts for [[substructures]]; a
// model listing itself is refused, not read forever).
#include "fuzz_input.hpp"
#include "io/files.hpp"
#include "io/model_file.hpp"

#include <utility>

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const std::filesystem::path examples = std::filesystem::path(JOINTID_SOURCE_DIR) / "examples";
  for (const auto& file :
       {examples / "portal_frame" / "portal.msh", examples / "matrices" / "k.mtx",
        examples / "matrices" / "m.mtx", examples / "matrices" / "dofs.txt"})
    std::filesystem::copy_file(file, jointid::fuzz::input_directory() / file.filename(),
                               std::filesystem::copy_options::overwrite_existing);
  std::filesystem::copy_file(std::filesystem::path(JOINTID_SOURCE_DIR) / "fuzz" / "corpus" /
                                 "fuzz_frf_csv" / "mobility.csv",
                             jointid::fuzz::input_directory() / "h.csv",
                             std::filesystem::copy_options::overwrite_existing);
  // Parts for [[substructures]]: the [frf] model of the seeds (its FRFs are h.csv), the [modal]
  // one and the [matrices] one (k.mtx, m.mtx, dofs.txt).
  const std::filesystem::path seeds =
      std::filesystem::path(JOINTID_SOURCE_DIR) / "fuzz" / "corpus" / "fuzz_model_file";
  for (const auto& [seed, part] :
       {std::pair{"frf.toml", "frf_part.toml"}, std::pair{"modal.toml", "modal_part.toml"},
        std::pair{"matrices.toml", "matrices_part.toml"}})
    std::filesystem::copy_file(seeds / seed, jointid::fuzz::input_directory() / part,
                               std::filesystem::copy_options::overwrite_existing);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 64 * 1024) return -1; // model files are small; larger inputs only slow the search
  const auto path = jointid::fuzz::input_file("model.toml", data, size);
  try {
    const auto file = jointid::io::read_model(path);
    (void)file;
  } catch (const jointid::io::Error&) {
  }
  return 0;
}
