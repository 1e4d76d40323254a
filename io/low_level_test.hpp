#pragma once
/// The inputs of a modal fit (`jointid modal-fit`, `jointid.modal_fit`): the low-level test's
/// time records (CSV records, universal files of time responses) or its FRF files (CSV FRF
/// tables, universal files of FRFs from one driving point), not both; and the fit itself from
/// them, so that both front ends read and refuse the same files with the same words.
#include "identify/measured_frfs.hpp"
#include "identify/modal_fit.hpp"
#include "identify/record.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace jointid::io {

/// What a file holds, from its first lines: a universal file (first non-blank line "-1") of
/// FRFs or of time responses; a CSV file by its header's first column, `t` (a record) or
/// `freq_hz` with NODE:DOF columns (an FRF table). A stepped-sine table (`freq_hz` with channel
/// columns) is refused (io::Error naming the file and what modal-fit reads).
enum class LowLevelInput { csv_record, uff_record, frf };
LowLevelInput low_level_input(const std::filesystem::path& path);

/// The test: records (given, or read from files) or FRF files.
struct LowLevelTest {
  std::vector<identify::Record> records;
  std::vector<std::filesystem::path> frf_files;
};

/// Adds the files to `test` as low_level_input() tells them apart. io::Error for a file given
/// twice (its blocks would count twice), and for records and FRF files together.
void add_low_level_files(LowLevelTest& test, const std::vector<std::filesystem::path>& paths);

/// How the FRFs are estimated and the modes fitted, with the front end's spelling of each
/// option: `cli` true names them "--band", "--max-order"; false "band", "max_order".
struct ModalFitArguments {
  double f0_hz = 0.0, f1_hz = 0.0;
  int modes = 0;                ///< 0: as many as the stabilisation diagram shows
  int max_order = 0;            ///< 0: automatic
  std::string spectra = "auto"; ///< auto, welch, periods or whole
  int segment = 0;              ///< Welch samples per segment; 0: automatic
  double period_s = 0.0;        ///< the records' period; 0: their # period_s
  bool cli = true;
};

/// Checks the arguments alone (io::Error naming the option and what was expected).
void check_modal_fit_arguments(const ModalFitArguments& a);

/// The FRFs (H1 from the records, or the FRF files read) and the modal fit, after the
/// arguments' checks and the test's (records or FRF files; --spectra, --segment and --period
/// only for records). The library's
/// refusals (std::invalid_argument naming the record, the band or the channels) become
/// io::Error; a fit that cannot give the modes is its status (ModalFit::status).
struct LowLevelFit {
  identify::MeasuredFrfs data;
  identify::ModalFit fit;
};
LowLevelFit fit_low_level_test(const LowLevelTest& test, const ModalFitArguments& a);

} // namespace jointid::io
