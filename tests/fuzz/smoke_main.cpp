// A fixed-seed run of a libFuzzer target without libFuzzer (any compiler): every corpus file
// as it is, then --runs mutants of them (bit flips, bytes that matter to text formats,
// insertions, deletions, copies and splices), each passed to LLVMFuzzerTestOneInput. The same
// seed gives the same inputs, so a failure reproduces; a target that traps fails the test.
// `make fuzz` runs the real fuzzer for longer.
//   TARGET_smoke [--runs N] [--seed S] [CORPUS_FILE_OR_DIR ...]
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

using Input = std::vector<std::uint8_t>;

struct Random {
  std::uint64_t state;
  std::uint64_t next() {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
  }
  std::size_t below(std::size_t n) { return n ? static_cast<std::size_t>(next() % n) : 0; }
};

void load(const std::filesystem::path& p, std::vector<Input>& corpus) {
  if (std::filesystem::is_directory(p)) {
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::recursive_directory_iterator(p))
      if (e.is_regular_file()) files.push_back(e.path());
    std::sort(files.begin(), files.end());  // the same order everywhere
    for (const auto& f : files) load(f, corpus);
    return;
  }
  if (std::filesystem::file_size(p) > (64u << 10)) return;  // seeds are small files
  std::ifstream in(p, std::ios::binary);
  corpus.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

Input mutate(const std::vector<Input>& corpus, Random& rng) {
  static const std::uint8_t kBytes[] = {0,   0xff, ',', '\n', '-', '+', '.', 'e', 'x', 'p', '0',  '1',  '9', ' ',
                                        '[', ']',  '=', '"',  '#', 'i', 'n', 'f', 'a', '_', '\r', 0x80, '\\'};
  Input in = corpus[rng.below(corpus.size())];
  const std::size_t edits = 1 + rng.below(4);
  for (std::size_t k = 0; k < edits; ++k) {
    const std::size_t at = rng.below(in.size() + 1);
    switch (rng.below(6)) {
      case 0:
        if (!in.empty()) in[rng.below(in.size())] ^= static_cast<std::uint8_t>(1u << rng.below(8));
        break;
      case 1:
        if (!in.empty()) in[rng.below(in.size())] = kBytes[rng.below(std::size(kBytes))];
        break;
      case 2:
        in.insert(in.begin() + static_cast<std::ptrdiff_t>(at), kBytes[rng.below(std::size(kBytes))]);
        break;
      case 3: {
        const std::size_t n = std::min(in.size() - std::min(at, in.size()), 1 + rng.below(16));
        in.erase(in.begin() + static_cast<std::ptrdiff_t>(at), in.begin() + static_cast<std::ptrdiff_t>(at + n));
        break;
      }
      case 4: {  // copy a piece of itself elsewhere (repeats lines, tables, keys)
        if (in.empty()) break;
        const std::size_t from = rng.below(in.size());
        const std::size_t n = std::min(in.size() - from, 1 + rng.below(64));
        const Input piece(in.begin() + static_cast<std::ptrdiff_t>(from),
                          in.begin() + static_cast<std::ptrdiff_t>(from + n));
        in.insert(in.begin() + static_cast<std::ptrdiff_t>(at), piece.begin(), piece.end());
        break;
      }
      default: {  // splice with another input
        const Input& other = corpus[rng.below(corpus.size())];
        const std::size_t from = rng.below(other.size() + 1);
        in.resize(at);
        in.insert(in.end(), other.begin() + static_cast<std::ptrdiff_t>(from), other.end());
        break;
      }
    }
  }
  return in;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t runs = 1000;
  std::uint64_t seed = 1;
  std::vector<Input> corpus{Input{}};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) {
      runs = std::strtoull(argv[++i], nullptr, 10);
    } else if (a == "--seed" && i + 1 < argc) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else {
      load(a, corpus);
    }
  }
  for (const Input& in : corpus) LLVMFuzzerTestOneInput(in.data(), in.size());
  Random rng{seed * 0x9e3779b97f4a7c15ULL + 1};
  for (std::size_t r = 0; r < runs; ++r) {
    const Input in = mutate(corpus, rng);
    LLVMFuzzerTestOneInput(in.data(), in.size());
  }
  std::printf("%zu corpus inputs and %zu mutants (seed %llu): no failure\n", corpus.size(), runs,
              static_cast<unsigned long long>(seed));
  return 0;
}
