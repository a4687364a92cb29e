#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace panmap {

/// panmap's default label space is ScanNet's NYU40 ids (1..40); 0 means unknown / unlabelled.
constexpr int32_t kUnknownClass = 0;
/// Largest NYU40 id.
constexpr int32_t kMaxNyu40Class = 40;

/// NYU40 class name of an id as spelled in ScanNet's table ("wall", "otherfurniture"), or
/// "unknown" outside 1..40.
std::string nyu40Name(int32_t class_id);

/// NYU40 id of a class name, matched case- and punctuation-insensitively; 0 if unknown.
int32_t nyu40IdFromName(const std::string& name);

/// True for the stuff classes (wall 1, floor 2, ceiling 22): they carry no instance.
bool isStuffClass(int32_t class_id);

/// ScanNet's 18 evaluated instance classes (DESIGN 7), ascending.
const std::vector<int32_t>& evaluatedClasses();

/// Lower-case letters and digits of a name, everything else dropped ("Night-Stand" ->
/// "nightstand"); the key of all forgiving name matches.
std::string normaliseName(const std::string& name);

}  // namespace panmap
