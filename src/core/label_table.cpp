#include "panmap/core/label_table.h"

#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"

namespace panmap {

LabelTable LabelTable::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot open label table " + path);
  LabelTable table;
  std::map<int32_t, int> first_line;  // a repeated id is a slip in the file, not an override
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::istringstream fields(line);
    std::string first;
    if (!(fields >> first)) continue;  // blank or comment-only line
    std::istringstream row(line);
    long long source_id = 0, panmap_class = 0;
    int is_thing = 0;
    if (!(row >> source_id >> panmap_class >> is_thing) || (is_thing != 0 && is_thing != 1) ||
        panmap_class < 0 || panmap_class > kMaxNyu40Class || source_id < INT32_MIN ||
        source_id > INT32_MAX) {
      throw Error(path + ":" + std::to_string(line_no) +
                  ": expected 'source_id panmap_class(0-40) is_thing(0/1) [name]'");
    }
    Entry entry;
    entry.panmap_class = static_cast<int32_t>(panmap_class);
    entry.is_thing = is_thing == 1;
    std::getline(row >> std::ws, entry.name);
    // A comment after the name leaves the whitespace before it.
    entry.name.erase(entry.name.find_last_not_of(" \t\r") + 1);
    const auto [seen, fresh] = first_line.emplace(static_cast<int32_t>(source_id), line_no);
    if (!fresh) {
      throw Error(path + ":" + std::to_string(line_no) + ": source id " +
                  std::to_string(source_id) + " already on line " + std::to_string(seen->second));
    }
    table.set(static_cast<int32_t>(source_id), entry);
  }
  if (table.size() == 0) throw Error("label table " + path + " has no rows");
  return table;
}

LabelTable LabelTable::nyu40Identity() {
  LabelTable table;
  for (int32_t id = 1; id <= kMaxNyu40Class; ++id) {
    table.set(id, Entry{id, !isStuffClass(id), nyu40Name(id)});
  }
  return table;
}

LabelTable LabelTable::contiguous() const {
  LabelTable table;
  int32_t index = 0;
  for (const auto& [source_id, entry] : entries_) table.set(index++, entry);
  return table;
}

std::optional<LabelTable::Entry> LabelTable::lookup(int32_t source_id) const {
  const auto it = entries_.find(source_id);
  if (it == entries_.end()) return std::nullopt;
  return it->second;
}

}  // namespace panmap
