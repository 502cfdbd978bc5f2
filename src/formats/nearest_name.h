#pragma once
// "Did you mean ...?" for misspelt keys and column names in the data formats.

#include <optional>
#include <string_view>
#include <vector>

namespace cdpr::formats {

// The candidate closest to `name` by edit distance (insert, delete or
// replace one character), if it is at most `max_edits` away; ties go to the
// earlier candidate.
std::optional<std::string_view> nearest_name(std::string_view name, const std::vector<std::string_view>& candidates,
                                             std::size_t max_edits = 2);

}  // namespace cdpr::formats
