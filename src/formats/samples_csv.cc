#include "src/formats/samples_csv.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "src/formats/nearest_name.h"
#include "src/formats/number_text.h"
#include "src/formats/text_file.h"
#include "src/formats/text_lines.h"

namespace cdpr::formats {
namespace {

// A measured quaternion may be off unit length by rounding in the pose
// source; beyond this (relative) it is a wrong column or a corrupt row.
constexpr double kUnitTolerance = 1e-3;
// Closer to unit than this, normalising would only flip the last bits and
// break the exact format -> parse round trip.
constexpr double kAlreadyUnit = 1e-15;

// Column order of the documented header; the file may order them freely.
enum Column { kSample, kX, kY, kZ, kQw, kQx, kQy, kQz, kFirstEncoder };
// The force column follows the encoders, the sigma columns follow the force.
constexpr int kFirstSigma = kFirstEncoder + kCableCount + 1;
constexpr int kSigmaCount = kCableCount + 3;

std::vector<std::string> column_names(int cable_count) {
  std::vector<std::string> names{"sample", "x", "y", "z", "qw", "qx", "qy", "qz"};
  for (int i = 0; i < cable_count; ++i) names.push_back("enc" + std::to_string(i));
  names.push_back("force");
  return names;
}

// The optional per-row sigmas (Sample::sigma), all together or none; they
// follow the required columns in the column numbering.
std::vector<std::string> sigma_column_names(int cable_count) {
  std::vector<std::string> names;
  for (int i = 0; i < cable_count; ++i) names.push_back("sigma_enc" + std::to_string(i));
  for (const char* name : {"sigma_force", "sigma_pos", "sigma_rot"}) names.emplace_back(name);
  return names;
}

std::vector<std::string> all_column_names(int cable_count) {
  std::vector<std::string> names = column_names(cable_count);
  for (std::string& name : sigma_column_names(cable_count)) names.push_back(std::move(name));
  return names;
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ",") + name;
  return text;
}

std::string quoted(std::string_view text) { return "'" + std::string(text) + "'"; }

std::string csv_number_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

std::string unknown_column_reason(std::string_view name, int file_column, int cable_count) {
  const std::string reason = "unknown column " + std::to_string(file_column);
  // An encoder of a cable the robot does not have: say how many it has.
  const std::string_view encoder = name.starts_with("sigma_") ? name.substr(6) : name;
  if (encoder.starts_with("enc") && parse_integer(encoder.substr(3))) {
    return reason + ": the robot has " + std::to_string(cable_count) + " cables, enc0..enc" +
           std::to_string(cable_count - 1);
  }
  const std::vector<std::string> known = all_column_names(cable_count);
  const auto nearest = nearest_name(name, std::vector<std::string_view>(known.begin(), known.end()));
  if (nearest) return reason + " (did you mean '" + std::string(*nearest) + "'?)";
  return reason + "; expected the columns " + joined(column_names(cable_count)) + " (in any order), optionally " +
         joined(sigma_column_names(cable_count));
}

// The header: for each file column, which documented column it is.
class Header {
 public:
  // Refuses empty, unknown and duplicate names, then names every missing
  // one (of the sigma columns only when some of them are there).
  static Expected<Header, FormatError> parse(const TextLine& line, const std::string& source, int cable_count) {
    const std::vector<std::string> expected = all_column_names(cable_count);
    Header header;
    std::map<std::string, int, std::less<>> seen;  // name -> 1-based file column
    for (const std::string_view field : split_fields(line.text, ',')) {
      const int file_column = static_cast<int>(header.names_.size()) + 1;
      const std::string name(field);
      const auto known = std::find(expected.begin(), expected.end(), name);
      if (name.empty()) return fail(line, source, "", "column " + std::to_string(file_column) + " has no name");
      if (known == expected.end()) return fail(line, source, name, unknown_column_reason(name, file_column, cable_count));
      if (const auto first = seen.find(name); first != seen.end()) {
        return fail(
            line, source, name,
            "duplicate column (columns " + std::to_string(first->second) + " and " + std::to_string(file_column) + ")");
      }
      seen.emplace(name, file_column);
      header.names_.push_back(name);
      header.column_of_field_.push_back(static_cast<int>(known - expected.begin()));
    }
    std::string missing;
    for (const std::string& name : column_names(cable_count)) {
      if (!seen.contains(name)) missing += (missing.empty() ? "" : ",") + name;
    }
    std::string missing_sigma;
    for (const std::string& name : sigma_column_names(cable_count)) {
      if (seen.contains(name)) {
        header.has_sigma_ = true;
      } else {
        missing_sigma += (missing_sigma.empty() ? "" : ",") + name;
      }
    }
    if (header.has_sigma_ && !missing_sigma.empty()) {
      missing += (missing.empty() ? "" : ",") + missing_sigma;
      return fail(line, source, missing, "missing columns in the header (the sigma columns come all together)");
    }
    if (!missing.empty()) {
      const bool several = missing.find(',') != std::string::npos;
      return fail(line, source, missing, several ? "missing columns in the header" : "missing column in the header");
    }
    return header;
  }

  std::size_t size() const { return names_.size(); }
  const std::string& name(std::size_t field) const { return names_[field]; }
  int column(std::size_t field) const { return column_of_field_[field]; }
  bool has_sigma() const { return has_sigma_; }

 private:
  static Unexpected<FormatError> fail(const TextLine& line, const std::string& source, std::string field,
                                      std::string reason) {
    return Unexpected{FormatError{source, line.number, std::move(field), std::move(reason)}};
  }

  std::vector<std::string> names_;
  std::vector<int> column_of_field_;
  bool has_sigma_ = false;
};

// One data row into a Sample; every value is checked, none is defaulted.
Expected<Sample, FormatError> parse_row(const TextLine& line, const Header& header, const std::string& source) {
  const auto fail = [&](std::string field, std::string reason) {
    return Unexpected{FormatError{source, line.number, std::move(field), std::move(reason)}};
  };
  const std::vector<std::string_view> fields = split_fields(line.text, ',');
  if (fields.size() != header.size()) {
    const std::string first_missing = fields.size() < header.size() ? header.name(fields.size()) : "";
    return fail(first_missing, "row has " + std::to_string(fields.size()) + " values but the header has " +
                                   std::to_string(header.size()) + " columns");
  }
  std::vector<double> values(static_cast<std::size_t>(kFirstSigma + kSigmaCount));
  std::int64_t id = 0;
  int sigmas_given = 0;
  std::string first_sigma_missing;
  for (std::size_t f = 0; f < fields.size(); ++f) {
    const std::string& name = header.name(f);
    const bool sigma_column = header.column(f) >= kFirstSigma;
    if (fields[f].empty() && sigma_column) {
      if (first_sigma_missing.empty()) first_sigma_missing = name;
      continue;
    }
    if (fields[f].empty()) return fail(name, "missing value");
    if (header.column(f) == kSample) {
      const std::optional<std::int64_t> parsed = parse_integer(fields[f]);
      if (!parsed || *parsed < std::numeric_limits<int>::min() || *parsed > std::numeric_limits<int>::max()) {
        return fail(name, "sample id must be an integer, got " + quoted(fields[f]));
      }
      id = *parsed;
      continue;
    }
    const std::optional<double> parsed = parse_number(fields[f]);
    if (!parsed) return fail(name, "not a number: " + quoted(fields[f]));
    if (!std::isfinite(*parsed)) return fail(name, "not a finite number: " + quoted(fields[f]));
    if (sigma_column && !(*parsed > 0.0)) return fail(name, "a sigma must be > 0, got " + quoted(fields[f]));
    if (sigma_column) ++sigmas_given;
    values[static_cast<std::size_t>(header.column(f))] = *parsed;
  }
  if (sigmas_given > 0 && !first_sigma_missing.empty()) {
    return fail(first_sigma_missing, "missing value (a row gives all its sigmas or none)");
  }

  Sample sample;
  sample.id = static_cast<int>(id);
  sample.position_world = Eigen::Vector3d(values[kX], values[kY], values[kZ]);
  sample.world_R_platform = Eigen::Quaterniond(values[kQw], values[kQx], values[kQy], values[kQz]);
  const double norm = sample.world_R_platform.norm();
  if (std::abs(norm - 1.0) > kUnitTolerance) {
    return fail("qw..qz",
                "quaternion norm " + csv_number_text(norm) + " is not 1 (tolerance " + csv_number_text(kUnitTolerance) + ")");
  }
  if (std::abs(norm - 1.0) > kAlreadyUnit) sample.world_R_platform.normalize();
  for (int i = 0; i < kCableCount; ++i) sample.encoder_m[i] = values[static_cast<std::size_t>(kFirstEncoder + i)];
  sample.force_n = values[static_cast<std::size_t>(kFirstEncoder + kCableCount)];
  if (sigmas_given > 0) {
    SampleSigmas& sigma = sample.sigma;
    for (int i = 0; i < kCableCount; ++i) sigma.encoder_m[i] = values[static_cast<std::size_t>(kFirstSigma + i)];
    sigma.force_n = values[static_cast<std::size_t>(kFirstSigma + kCableCount)];
    sigma.position_m = values[static_cast<std::size_t>(kFirstSigma + kCableCount + 1)];
    sigma.orientation_rad = values[static_cast<std::size_t>(kFirstSigma + kCableCount + 2)];
  }
  return sample;
}

}  // namespace

Expected<std::vector<Sample>, FormatError> parse_samples_csv(std::string_view text, const std::string& source,
                                                             int cable_count) {
  if (cable_count != kCableCount) {
    return Unexpected{FormatError{source, 0, "",
                                  "cannot read samples of " + std::to_string(cable_count) +
                                      " cables; the solver handles exactly " + std::to_string(kCableCount)}};
  }
  const std::vector<TextLine> lines = content_lines(text);
  if (lines.empty()) {
    return Unexpected{
        FormatError{source, 0, "", "no header line (expected " + joined(column_names(cable_count)) + ")"}};
  }
  const auto header = Header::parse(lines.front(), source, cable_count);
  if (!header) return Unexpected{header.error()};
  if (lines.size() == 1) return Unexpected{FormatError{source, lines.front().number, "", "no data rows"}};

  std::vector<Sample> samples;
  std::map<int, int> line_of_id;
  for (std::size_t k = 1; k < lines.size(); ++k) {
    auto sample = parse_row(lines[k], *header, source);
    if (!sample) return Unexpected{sample.error()};
    const auto [first, inserted] = line_of_id.emplace(sample->id, lines[k].number);
    if (!inserted) {
      return Unexpected{FormatError{source, lines[k].number, "sample",
                                    "duplicate sample id " + std::to_string(sample->id) + " (first on line " +
                                        std::to_string(first->second) + ")"}};
    }
    samples.push_back(*sample);
  }
  return samples;
}

Expected<std::vector<Sample>, FormatError> read_samples_csv(const std::string& path, int cable_count) {
  return parse_file(path, [cable_count](std::string_view text, const std::string& source) {
    return parse_samples_csv(text, source, cable_count);
  });
}

std::string format_samples_csv(const std::vector<Sample>& samples) {
  const bool any_sigma = std::any_of(samples.begin(), samples.end(), [](const Sample& s) { return s.has_own_sigma(); });
  std::string out =
      "# samples.csv (docs/FORMATS.md): position [m] world, quaternion platform->world, encoders [m], "
      "reference force [N]";
  out += any_sigma ? ", 1-sigma of each row's readings [m, N, m, rad]\n" : "\n";
  out += joined(any_sigma ? all_column_names(kCableCount) : column_names(kCableCount)) + "\n";
  for (const Sample& s : samples) {
    const Eigen::Quaterniond& q = s.world_R_platform;
    out += std::to_string(s.id);
    for (const double value :
         {s.position_world.x(), s.position_world.y(), s.position_world.z(), q.w(), q.x(), q.y(), q.z()}) {
      out += "," + shortest_text(value);
    }
    for (const double reading : s.encoder_m) out += "," + shortest_text(reading);
    out += "," + shortest_text(s.force_n);
    if (any_sigma && s.has_own_sigma()) {
      for (const double sigma : s.sigma.encoder_m) out += "," + shortest_text(sigma);
      for (const double sigma : {s.sigma.force_n, s.sigma.position_m, s.sigma.orientation_rad}) {
        out += "," + shortest_text(sigma);
      }
    } else if (any_sigma) {
      out += std::string(kSigmaCount, ',');  // robot.toml's sigmas weight this row
    }
    out += "\n";
  }
  return out;
}

}  // namespace cdpr::formats
