#pragma once
/// What kind of test a time record is, told from its comments or, where they say nothing, from
/// its force channel — every step O(N log N) in the record's length N:
///  - a **sine test**: one line (with its harmonics) holds the force's power; its frequency is
///    the Hann-windowed spectrum's peak, interpolated, then refined by least squares;
///  - a **periodic broadband test** (e.g. a multisine): the force repeats with a period of a
///    whole number of samples (its normalised autocorrelation, by FFT, near 1 at the period and
///    at every multiple of it in the record);
///  - a **sweep**: the frequency of the force's largest line rises or falls steadily through
///    the record (a spectrogram of non-overlapping windows).
/// Anything else (random excitation, a single period of a multisine, an impact) is none of them:
/// classify() refuses it, naming the record and the comment that would declare it.
#include "identify/record.hpp"

#include <string>

namespace jointid::identify {

enum class RecordKind { sine, periodic, sweep };
const char* to_string(RecordKind kind); ///< "sine test", "periodic test", "sweep"

struct RecordClass {
  RecordKind kind = RecordKind::sine;
  bool declared = false;    ///< by the record's comments (else detected)
  double frequency_hz = 0;  ///< sine: the excitation frequency, Hz
  int period_samples = 0;   ///< periodic: samples in one period
  double period_s = 0;      ///< periodic: the period, s
  double sweep_from_hz = 0; ///< sweep: the frequency at its start and end (spectrogram), Hz
  double sweep_to_hz = 0;
  std::string evidence; ///< how it was told, in words (for messages)
};

/// The record's kind. Throws std::invalid_argument naming the record: no force channel, every
/// force zero, a declared period that does not hold a whole number of samples or is longer than
/// the record, or a force that is none of the three kinds (the message says which comment would
/// declare it).
RecordClass classify(const Record& record);

/// The force channel the record is told by: the first one that is not zero in every sample.
/// Throws as classify().
const Channel& driving_force(const Record& record);

} // namespace jointid::identify
