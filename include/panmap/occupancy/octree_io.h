#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include <octomap/OcTree.h>

namespace panmap {

// OctoMap's binary formats, read defensively. OctoMap's own readers trust their input: a
// truncated or corrupted stream makes readBinaryNode read past the end and recurse on
// whatever it finds. These functions check a stream's structure before OctoMap sees it.
//
// Writers never touch the tree they are given (OctoMap's writeBinary() would overwrite its
// probabilities with maximum-likelihood values); they serialise a pruned maximum-likelihood
// copy, so the same tree always gives the same bytes.

/// The tree's free / occupied bits as OctoMap's writeBinaryData() stream (no header): the
/// `data` of a PANMAP_OCTOMAP message with binary = true. An empty tree gives "".
std::string toBinaryData(const octomap::OcTree& tree);

/// A tree of the given resolution from a writeBinaryData() stream. Throws Error when the
/// stream is malformed (truncated, trailing bytes, children below the finest level).
/// @param resolution_m leaf size the stream was written at, metres (> 0)
std::unique_ptr<octomap::OcTree> treeFromBinaryData(const std::string& data, double resolution_m);

/// The bytes of an OctoMap .bt file (header with id, size and resolution, then the binary
/// data): what octovis, convert_octree and OcTree(filename) read.
std::string toBtBytes(const octomap::OcTree& tree);

/// A tree from the bytes of a .bt file. Throws Error naming `what` and the problem.
/// @param what name of the source for messages (a path, "message")
std::unique_ptr<octomap::OcTree> treeFromBtBytes(const std::string& bytes, const std::string& what);

/// Writes a .bt file, replaced whole (writeFileAtomically). Throws Error naming the path when it
/// cannot be written.
void writeBtFile(const octomap::OcTree& tree, const std::string& path);

/// Reads a .bt file. Throws Error naming the path when it is missing or malformed.
std::unique_ptr<octomap::OcTree> readBtFile(const std::string& path);

/// Number of nodes a writeBinaryData() stream describes, or -1 when it is malformed (see
/// treeFromBinaryData). "" describes the empty tree (0 nodes).
long countBinaryDataNodes(const std::string& data);

}  // namespace panmap
