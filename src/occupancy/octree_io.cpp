#include "panmap/occupancy/octree_io.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "panmap/core/error.h"
#include "panmap/io/atomic_file.h"

namespace panmap {
namespace {

// OctoMap trees have 16 levels below the root; leaves at level 16 cannot have children.
constexpr int kTreeDepth = 16;
constexpr const char* kBtHeader = "# Octomap OcTree binary file";

// Walks one node of a writeBinaryData() stream in the writer's order (the node's two bytes,
// then the nodes of its children that have children, child 0 first). Two bits per child:
// 00 unknown, 01 occupied leaf, 10 free leaf, 11 inner node.
bool walkNode(const std::string& data, size_t* pos, int depth, long* nodes) {
  if (*pos + 2 > data.size()) return false;
  const unsigned bits = static_cast<unsigned char>(data[*pos]) |
                        static_cast<unsigned>(static_cast<unsigned char>(data[*pos + 1])) << 8;
  *pos += 2;
  // The writer only marks a node as inner when it has a child; the root may be childless.
  if (bits == 0 && depth > 0) return false;
  int num_inner = 0;
  for (int child = 0; child < 8; ++child) {
    const unsigned code = (bits >> (2 * child)) & 3u;
    if (code != 0) ++*nodes;
    num_inner += code == 3u;
  }
  if (num_inner > 0 && depth + 1 >= kTreeDepth) return false;
  for (int k = 0; k < num_inner; ++k) {
    if (!walkNode(data, pos, depth + 1, nodes)) return false;
  }
  return true;
}

// A pruned maximum-likelihood copy: the canonical form of what the tree says about space.
std::unique_ptr<octomap::OcTree> canonicalCopy(const octomap::OcTree& tree) {
  auto copy = std::make_unique<octomap::OcTree>(tree);
  copy->toMaxLikelihood();
  copy->prune();
  return copy;
}

std::string readWholeFile(const std::string& path) {
  std::error_code ec;
  // A folder opens as a stream and then fails inside libstdc++ ("basic_filebuf::underflow").
  if (std::filesystem::is_directory(path, ec)) throw Error(path + " is a folder, not a .bt file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(path + ": read error");
  return bytes;
}

}  // namespace

long countBinaryDataNodes(const std::string& data) {
  if (data.empty()) return 0;
  size_t pos = 0;
  long nodes = 1;  // the root
  if (!walkNode(data, &pos, 0, &nodes) || pos != data.size()) return -1;
  return nodes;
}

std::string toBinaryData(const octomap::OcTree& tree) {
  std::ostringstream out(std::ios::binary);
  canonicalCopy(tree)->writeBinaryData(out);
  return out.str();
}

std::unique_ptr<octomap::OcTree> treeFromBinaryData(const std::string& data, double resolution_m) {
  if (!(resolution_m > 0.0 && std::isfinite(resolution_m))) {
    throw Error("octree resolution must be positive and finite");
  }
  const long nodes = countBinaryDataNodes(data);
  if (nodes < 0) {
    throw Error("malformed octree data (" + std::to_string(data.size()) + " bytes)");
  }
  auto tree = std::make_unique<octomap::OcTree>(resolution_m);
  if (nodes == 0) return tree;
  std::istringstream in(data, std::ios::binary);
  tree->readBinaryData(in);
  if (static_cast<long>(tree->size()) != nodes) throw Error("octree data: node count mismatch");
  return tree;
}

std::string toBtBytes(const octomap::OcTree& tree) {
  const std::unique_ptr<octomap::OcTree> canonical = canonicalCopy(tree);
  // OctoMap's writeBinaryConst header, written here because the library's version also
  // reports progress on stderr.
  std::ostringstream out(std::ios::binary);
  out << kBtHeader
      << "\n# (feel free to add / change comments, but leave the first line as it "
         "is!)\n#\n"
      << "id " << canonical->getTreeType() << "\nsize " << canonical->size() << "\nres "
      << canonical->getResolution() << "\ndata\n";
  canonical->writeBinaryData(out);
  return out.str();
}

std::unique_ptr<octomap::OcTree> treeFromBtBytes(const std::string& bytes,
                                                 const std::string& what) {
  // The header as OctoMap writes and reads it: the magic first line, '#' comments, then
  // "id", "size", "res" in any order, then "data" and the stream.
  std::istringstream in(bytes, std::ios::binary);
  std::string line;
  if (!std::getline(in, line) || line.compare(0, std::string(kBtHeader).size(), kBtHeader) != 0) {
    throw Error(what + ": not an OctoMap .bt file (first line is not '" + kBtHeader + "')");
  }
  std::string id;
  long size = -1;
  double resolution_m = 0.0;
  bool data_seen = false;
  while (!data_seen && std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string token;
    fields >> token;
    if (token == "id") {
      fields >> id;
    } else if (token == "size") {
      fields >> size;
    } else if (token == "res") {
      fields >> resolution_m;
    } else if (token == "data") {
      data_seen = true;
    } else {
      throw Error(what + ": unexpected .bt header line '" + line + "'");
    }
    if (fields.fail()) throw Error(what + ": bad .bt header line '" + line + "'");
  }
  if (!data_seen) throw Error(what + ": .bt header has no 'data' line");
  if (id != "OcTree") throw Error(what + ": tree type '" + id + "' is not OcTree");
  if (size < 0) throw Error(what + ": .bt header has no node count ('size')");
  if (!(resolution_m > 0.0 && std::isfinite(resolution_m))) {
    throw Error(what + ": .bt header has no positive resolution ('res')");
  }
  // A header ending without a newline after "data" leaves the stream at its end.
  const std::string data = in.eof() ? std::string() : bytes.substr(static_cast<size_t>(in.tellg()));
  const long nodes = countBinaryDataNodes(data);
  if (nodes < 0) throw Error(what + ": malformed or truncated octree data");
  if (nodes != size) {
    throw Error(what + ": header says " + std::to_string(size) + " nodes, the data holds " +
                std::to_string(nodes));
  }
  return treeFromBinaryData(data, resolution_m);
}

void writeBtFile(const octomap::OcTree& tree, const std::string& path) {
  writeFileAtomically(path, toBtBytes(tree));
}

std::unique_ptr<octomap::OcTree> readBtFile(const std::string& path) {
  return treeFromBtBytes(readWholeFile(path), path);
}

}  // namespace panmap
