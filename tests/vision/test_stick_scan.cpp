// The stick scan: a stick comes from a stranger, so every test here builds a small
// hostile tree in a fresh temp folder — links out of the tree, loops, FIFOs, device nodes, deep nesting,
// floods of entries and documents, empty, mislabelled and oversized files, names that are not UTF-8 or
// carry bidi and control characters — and checks what the scan lists, what it refuses and why, that every
// limit stops it with complete=false, and that it never follows a link, blocks, or changes the tree.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/mount.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "hk/error.hpp"
#include "test_paths.hpp"
#include "vision/intake.hpp"
#include "vision/stick_scan.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;

const std::string kData = HK_TEST_DATA_DIR;
const std::string kPngMagic("\x89PNG\r\n\x1a\n", 8);

/// A fresh folder under the test temp dir, removed with its contents at the end (links are removed,
/// not followed).
class TempTree {
 public:
  TempTree() {
    std::string tmpl = ::testing::TempDir();
    if (tmpl.empty() || tmpl.back() != '/') tmpl += '/';
    tmpl += "hk_stick_XXXXXX";
    std::vector<char> buf(tmpl.begin(), tmpl.end());
    buf.push_back('\0');
    if (::mkdtemp(buf.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    root_ = buf.data();
  }
  ~TempTree() {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  TempTree(const TempTree&) = delete;
  TempTree& operator=(const TempTree&) = delete;

  const std::string& root() const { return root_; }
  std::string operator/(const std::string& rel) const { return root_ + "/" + rel; }

  /// Writes `bytes` at `rel`, making its folders.
  void write(const std::string& rel, const std::string& bytes) const {
    const std::string p = *this / rel;
    fs::create_directories(fs::path(p).parent_path());
    std::ofstream(p, std::ios::binary) << bytes;
  }
  /// Copies a file from tests/data to `rel`.
  void copy(const std::string& data_file, const std::string& rel) const { write(rel, slurp(kData + "/" + data_file)); }
  void mkdir(const std::string& rel) const { fs::create_directories(*this / rel); }
  void symlink(const std::string& target, const std::string& rel) const {
    ASSERT_EQ(::symlink(target.c_str(), (*this / rel).c_str()), 0) << std::strerror(errno);
  }

  static std::string slurp(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  }

 private:
  std::string root_;
};

/// A tiny file the scan takes for a PNG (only its magic bytes are read).
std::string tiny_png() { return kPngMagic + std::string(8, '\0'); }

/// True when `s` is well-formed UTF-8 (no overlongs, surrogates, or values above U+10FFFF).
bool valid_utf8(const std::string& s) {
  const auto* p = reinterpret_cast<const unsigned char*>(s.data());
  const std::size_t n = s.size();
  for (std::size_t i = 0; i < n;) {
    const unsigned c = p[i];
    std::size_t len;
    std::uint32_t cp;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      len = 2, cp = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      len = 3, cp = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      len = 4, cp = c & 0x07;
    } else {
      return false;
    }
    if (i + len > n) return false;
    for (std::size_t k = 1; k < len; ++k) {
      if ((p[i + k] & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (p[i + k] & 0x3F);
    }
    const std::uint32_t min = len == 2 ? 0x80 : len == 3 ? 0x800 : 0x10000;
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += len;
  }
  return true;
}

/// True when `s` is safe to show on one line: valid UTF-8, no C0/DEL/C1, no bidi or zero-width controls.
bool safe_one_line(const std::string& s) {
  if (!valid_utf8(s)) return false;
  for (unsigned char c : s) {
    if (c < 0x20 || c == 0x7F) return false;
  }
  for (const char* bad : {"\xC2\x80", "\xC2\x85", "\xC2\x9F", "\xE2\x80\xAE", "\xE2\x80\xAD", "\xE2\x81\xA6",
                          "\xE2\x80\x8B", "\xEF\xBB\xBF", "\xE2\x80\x8E", "\xD8\x9C", "\xE2\x80\xA8"}) {
    if (s.find(bad) != std::string::npos) return false;
  }
  return true;
}

std::vector<std::string> doc_paths(const StickScan& s) {
  std::vector<std::string> v;
  for (const auto& d : s.documents) v.push_back(d.path);
  return v;
}

const StickDocument* find_doc(const StickScan& s, const std::string& path) {
  for (const auto& d : s.documents) {
    if (d.path == path) return &d;
  }
  return nullptr;
}

/// The reason `path` (display form) was refused, or "" if it was not.
std::string refusal(const StickScan& s, const std::string& path) {
  for (const auto& r : s.refused) {
    if (r.path == path) return r.reason;
  }
  return "";
}

/// The problem named by read_stick_file, or "" when it read the file.
std::string read_error(const std::string& root, const std::string& rel, std::int64_t max_bytes = 1 << 30) {
  try {
    (void)read_stick_file(root, rel, max_bytes);
    return "";
  } catch (const StickError& e) {
    return e.what();
  }
}

/// Every entry under `root` (links not followed) with its type, size, mtime and ctime [ns].
std::map<std::string, std::tuple<unsigned, long long, long long, long long>> listing(const std::string& root) {
  std::map<std::string, std::tuple<unsigned, long long, long long, long long>> out;
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator(); ++it) {
    struct stat st;
    if (::lstat(it->path().c_str(), &st) != 0) continue;
    out[it->path().string()] = {st.st_mode, static_cast<long long>(st.st_size),
                                st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec,
                                st.st_ctim.tv_sec * 1000000000LL + st.st_ctim.tv_nsec};
  }
  return out;
}

/// Every refusal is one line with a safe path; stopped_by agrees with complete and ends `refused`.
void expect_well_formed(const StickScan& s, const ScanLimits& limits) {
  EXPECT_LE(s.entries_scanned, limits.max_entries);
  EXPECT_LE(static_cast<long>(s.documents.size()), limits.max_documents);
  EXPECT_TRUE(std::is_sorted(s.documents.begin(), s.documents.end(),
                             [](const auto& a, const auto& b) { return a.path < b.path; }));
  for (const auto& r : s.refused) {
    EXPECT_TRUE(safe_one_line(r.path)) << r.path;
    EXPECT_TRUE(safe_one_line(r.reason)) << r.reason;
    EXPECT_FALSE(r.reason.empty()) << r.path;
  }
  for (const auto& d : s.documents) {
    EXPECT_TRUE(safe_one_line(d.display_name)) << d.display_name;
    EXPECT_EQ(d.display_name, safe_display_name(d.path));
    EXPECT_GT(d.bytes, 0);
    EXPECT_LE(d.bytes, limits.max_file_bytes);
  }
  if (s.complete) {
    EXPECT_TRUE(s.stopped_by.empty());
  } else {
    EXPECT_FALSE(s.stopped_by.empty());
    ASSERT_FALSE(s.refused.empty());
    EXPECT_EQ(s.refused.back().path, "");
    EXPECT_EQ(s.refused.back().reason, s.stopped_by);
  }
  EXPECT_GE(s.seconds, 0.0);
}

// ---------------------------------------------------------------------------------------------------------

TEST(StickSafeName, GoldenValues) {
  const std::string fffd = "\xEF\xBF\xBD";
  EXPECT_EQ(safe_display_name("horse.png"), "horse.png");
  EXPECT_EQ(safe_display_name("Ferien/Pferd groß.png"), "Ferien/Pferd groß.png");
  EXPECT_EQ(safe_display_name(""), "");
  // Latin-1 é is not UTF-8: one replacement character.
  EXPECT_EQ(safe_display_name("caf\xe9.png"), "caf" + fffd + ".png");
  // RIGHT-TO-LEFT OVERRIDE (U+202E) would show "photoexe.png"; removed, the real order shows.
  EXPECT_EQ(safe_display_name("photo\xE2\x80\xAEgnp.exe"), "photognp.exe");
  // Every bidi control, zero-width and BOM character is removed.
  EXPECT_EQ(safe_display_name("a\xE2\x80\x8E"
                              "b\xE2\x80\x8F"
                              "c\xE2\x80\xAA"
                              "d\xE2\x81\xA6"
                              "e\xE2\x81\xA9"
                              "f\xD8\x9C"
                              "g\xE2\x80\x8B"
                              "h\xE2\x80\x8D"
                              "i\xEF\xBB\xBF"
                              "j"),
            "abcdefghij");
  // C0 controls (newline, tab, ESC), DEL and C1 (NEL U+0085) go; the text stays on one line.
  EXPECT_EQ(safe_display_name("line\nbreak\r\t\x1b[31mred\x7f.png"), "linebreak[31mred.png");
  EXPECT_EQ(safe_display_name("x\xC2\x85y\xC2\x9Fz"), "xyz");
  // Line and paragraph separators go too.
  EXPECT_EQ(safe_display_name("a\xE2\x80\xA8"
                              "b\xE2\x80\xA9"
                              "c"),
            "abc");
  // Ill-formed UTF-8: one U+FFFD per maximal subpart.
  EXPECT_EQ(safe_display_name("\xC0\xAF"), fffd + fffd);                        // overlong '/': C0 and AF start nothing
  EXPECT_EQ(safe_display_name("\xED\xA0\x80"), fffd + fffd + fffd);             // surrogate U+D800
  EXPECT_EQ(safe_display_name("\xF4\x90\x80\x80"), fffd + fffd + fffd + fffd);  // above U+10FFFF
  EXPECT_EQ(safe_display_name("ab\xE2\x82"), "ab" + fffd);                      // truncated €: one subpart
  EXPECT_EQ(safe_display_name("\xE2\x82"
                              "x"),
            fffd + "x");
  EXPECT_EQ(safe_display_name("\xFF\xFE"), fffd + fffd);
  // Valid 2-, 3- and 4-byte characters stay.
  EXPECT_EQ(safe_display_name("\xC3\xA9\xE2\x82\xAC\xF0\x9F\x90\xB4"), "\xC3\xA9\xE2\x82\xAC\xF0\x9F\x90\xB4");
  // Nothing left of a non-empty name: one replacement character, never "".
  EXPECT_EQ(safe_display_name("\x01\x02\n"), fffd);
  // Length: 255 bytes stay; longer keeps the longest prefix of <= 252 bytes on a boundary, then "…".
  const std::string ell = "\xE2\x80\xA6";
  EXPECT_EQ(safe_display_name(std::string(255, 'a')), std::string(255, 'a'));
  EXPECT_EQ(safe_display_name(std::string(256, 'a')), std::string(252, 'a') + ell);
  EXPECT_EQ(safe_display_name(std::string(100000, 'a')), std::string(252, 'a') + ell);
  std::string e127, e126, yen86, yen84, horse64, horse63;
  for (int i = 0; i < 127; ++i) e127 += "\xC3\xA9";  // é, 254 bytes
  for (int i = 0; i < 126; ++i) e126 += "\xC3\xA9";
  for (int i = 0; i < 86; ++i) yen86 += "\xE6\x97\xA5";  // 日, 258 bytes
  for (int i = 0; i < 84; ++i) yen84 += "\xE6\x97\xA5";
  for (int i = 0; i < 64; ++i) horse64 += "\xF0\x9F\x90\xB4";  // 🐴, 256 bytes
  for (int i = 0; i < 63; ++i) horse63 += "\xF0\x9F\x90\xB4";
  EXPECT_EQ(safe_display_name(e127), e127);
  EXPECT_EQ(safe_display_name(e127 + "\xC3\xA9"), e126 + ell);  // 256 bytes → 252 + 3
  EXPECT_EQ(safe_display_name(yen86), yen84 + ell);             // 258 → 252 + 3
  EXPECT_EQ(safe_display_name(horse64), horse63 + ell);         // 256 → 252 + 3
  EXPECT_EQ(safe_display_name("a" + horse64), "a" + std::string(horse63.substr(0, 248)) + ell);  // 1 + 62*4 = 249 ≤ 252
  // Controls removed before measuring: 300 bytes of which 100 are controls → 200, unchanged.
  std::string mixed;
  for (int i = 0; i < 100; ++i)
    mixed +=
        "a\x01"
        "b";
  EXPECT_EQ(safe_display_name(mixed).size(), 200u);
}

TEST(StickSniff, MagicBytesDecideTheKind) {
  using std::string_view;
  EXPECT_EQ(sniff_document_format(kPngMagic), "png");
  EXPECT_EQ(sniff_document_format(kPngMagic.substr(0, 7)), "");
  EXPECT_EQ(sniff_document_format("\xFF\xD8\xFF\xE0"), "jpeg");
  EXPECT_EQ(sniff_document_format("\xFF\xD8"), "");
  EXPECT_EQ(sniff_document_format(string_view("II*\0\x08\0\0\0", 8)), "tiff");
  EXPECT_EQ(sniff_document_format(string_view("MM\0*\0\0\0\x08", 8)), "tiff");
  EXPECT_EQ(sniff_document_format(string_view("II+\0\x08\0\0\0", 8)), "tiff");
  EXPECT_EQ(sniff_document_format(string_view("MM\0+\0\x08\0\0", 8)), "tiff");
  EXPECT_EQ(sniff_document_format("RIFF\x10\x20\x30\x40WEBPVP8 "), "webp");
  EXPECT_EQ(sniff_document_format("RIFF\x10\x20\x30\x40WAVEfmt "), "");
  EXPECT_EQ(sniff_document_format("%PDF-1.7\n"), "pdf");
  EXPECT_EQ(sniff_document_format("%PDF"), "");
  // BMP: "BM" with a known DIB header size (40) at offset 14; text starting "BM" is not a picture.
  EXPECT_EQ(sniff_document_format(string_view("BM\x36\x10\0\0\0\0\0\0\x36\0\0\0\x28\0", 16)), "bmp");
  EXPECT_EQ(sniff_document_format(string_view("BM\x36\x10\0\0\0\0\0\0\x1a\0\0\0\x0c\0", 16)), "bmp");
  EXPECT_EQ(sniff_document_format("BMW owners' club newsletter"), "");
  EXPECT_EQ(sniff_document_format("BM"), "bmp");  // a 2-byte file: all there is to go on
  EXPECT_EQ(sniff_document_format(""), "");
  EXPECT_EQ(sniff_document_format("hello, this is not a PDF\n"), "");
}

TEST(StickScan, GoodStickListsPicturesAndPdfByMagicBytesNotNames) {
  TempTree t;
  t.copy("images/horse.png", "horse.png");
  t.copy("images/butterfly.jpg", "Fotos/butterfly.jpg");
  t.copy("images/apple.jpg", "Fotos/2023/Sommer/apple.jpg");
  t.copy("documents/horse_and_page.pdf", "Dokumente/horse_and_page.pdf");
  t.copy("images/camera.png", "Fotos/notes.txt");               // a PNG with a wrong name: found as png
  t.write("Dokumente/fake.pdf", "hello, this is not a PDF\n");  // a text with a PDF's name: refused
  t.write("README.txt", "just text\n");
  const ScanLimits limits;
  const StickScan s = scan_stick(t.root(), limits);
  expect_well_formed(s, limits);
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(doc_paths(s), (std::vector<std::string>{"Dokumente/horse_and_page.pdf", "Fotos/2023/Sommer/apple.jpg",
                                                    "Fotos/butterfly.jpg", "Fotos/notes.txt", "horse.png"}));
  // Entries: 7 files and 4 folders (Fotos, Fotos/2023, Fotos/2023/Sommer, Dokumente; the root is not one).
  EXPECT_EQ(s.entries_scanned, 7 + 4);
  const StickDocument* pdf = find_doc(s, "Dokumente/horse_and_page.pdf");
  ASSERT_NE(pdf, nullptr);
  EXPECT_EQ(pdf->kind, DocumentKind::Pdf);
  EXPECT_EQ(pdf->format, "pdf");
  const StickDocument* txt = find_doc(s, "Fotos/notes.txt");
  ASSERT_NE(txt, nullptr);
  EXPECT_EQ(txt->kind, DocumentKind::Image);
  EXPECT_EQ(txt->format, "png");
  EXPECT_EQ(find_doc(s, "Fotos/butterfly.jpg")->format, "jpeg");
  EXPECT_EQ(refusal(s, "Dokumente/fake.pdf"), "not a picture or PDF (unknown format)");
  EXPECT_EQ(refusal(s, "README.txt"), "not a picture or PDF (unknown format)");
  // Every document reads back whole and equal to the file; its size is the file's.
  for (const auto& d : s.documents) {
    const std::string want = TempTree::slurp(t / d.path);
    EXPECT_EQ(d.bytes, static_cast<std::int64_t>(want.size())) << d.path;
    EXPECT_EQ(d.display_name, d.path);
    const std::vector<std::uint8_t> got = read_stick_file(t.root(), d.path, limits.max_file_bytes);
    EXPECT_EQ(std::string(got.begin(), got.end()), want) << d.path;
  }
  // A second scan of the unchanged stick gives the same answer.
  const StickScan again = scan_stick(t.root(), limits);
  EXPECT_EQ(doc_paths(again), doc_paths(s));
  ASSERT_EQ(again.refused.size(), s.refused.size());
  for (std::size_t i = 0; i < s.refused.size(); ++i) EXPECT_EQ(again.refused[i].path, s.refused[i].path);
}

TEST(StickScan, HiddenAndSystemEntriesAreRefusedNotListed) {
  TempTree t;
  t.write("horse.png", tiny_png());
  t.write("._horse.png", tiny_png());  // AppleDouble next to it (even with a PNG's first bytes)
  t.write("Fotos/._pic.jpg", "\x00\x05\x16\x07" + std::string(12, '\0'));
  t.write(".Trash-1000/files/old.png", tiny_png());
  t.write(".fseventsd/fseventsd-uuid", "x");
  t.write("System Volume Information/IndexerVolumeGuid", tiny_png());
  t.write(".hidden.png", tiny_png());
  const ScanLimits limits;
  const StickScan s = scan_stick(t.root(), limits);
  expect_well_formed(s, limits);
  EXPECT_EQ(doc_paths(s), std::vector<std::string>{"horse.png"});
  EXPECT_NE(refusal(s, "._horse.png").find("macOS"), std::string::npos);
  EXPECT_NE(refusal(s, "Fotos/._pic.jpg").find("macOS"), std::string::npos);
  EXPECT_EQ(refusal(s, ".Trash-1000"), "a hidden folder (name starts with '.'), not entered");
  EXPECT_EQ(refusal(s, ".fseventsd"), "a hidden folder (name starts with '.'), not entered");
  EXPECT_EQ(refusal(s, ".hidden.png"), "a hidden file (name starts with '.'), not listed");
  EXPECT_EQ(refusal(s, "System Volume Information"), "a Windows system folder, not entered");
  EXPECT_EQ(refusal(s, ".Trash-1000/files"), "");  // not entered, so nothing inside is looked at
}

TEST(StickScan, SymbolicLinksAreRefusedAndNeverFollowed) {
  TempTree t, outside;
  outside.copy("images/horse.png", "secret.png");
  outside.copy("images/butterfly.jpg", "Ordner/inside.jpg");
  t.copy("images/apple.jpg", "apple.jpg");
  t.mkdir("sub");
  t.symlink(outside / "secret.png", "outside.png");  // a file outside the tree
  t.symlink("/etc/shadow", "shadow.png");            // a system file
  t.symlink(outside / "Ordner", "Ordner");           // a folder outside
  t.symlink("../apple.jpg", "sub/up.jpg");           // inside, but still a link
  t.symlink("loop", "loop");                         // a loop on itself
  t.symlink("b", "a");                               // and a loop of two
  t.symlink("a", "b");
  t.symlink("../../../../../../../../../../..", "sub/root");  // towards /
  t.symlink("/proc/self/root", "magic");                      // a magic link
  const ScanLimits limits;
  const StickScan s = scan_stick(t.root(), limits);
  expect_well_formed(s, limits);
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(doc_paths(s), std::vector<std::string>{"apple.jpg"});
  for (const char* link :
       {"outside.png", "shadow.png", "Ordner", "sub/up.jpg", "loop", "a", "b", "sub/root", "magic"}) {
    EXPECT_EQ(refusal(s, link), "a symbolic link (links are not followed)") << link;
  }
  EXPECT_EQ(s.entries_scanned, 11);  // apple.jpg, sub, 7 links at the root level and 2 in sub
  // read_stick_file refuses links, paths through linked folders, "..", absolute and odd paths.
  EXPECT_NE(read_error(t.root(), "outside.png").find("symbolic link"), std::string::npos);
  EXPECT_NE(read_error(t.root(), "shadow.png").find("symbolic link"), std::string::npos);
  EXPECT_NE(read_error(t.root(), "Ordner/inside.jpg").find("symbolic link"), std::string::npos);
  EXPECT_NE(read_error(t.root(), "loop").find("symbolic link"), std::string::npos);
  EXPECT_NE(read_error(t.root(), "magic/etc/passwd").find("symbolic link"), std::string::npos);
  EXPECT_NE(read_error(t.root(), "sub/root/etc/passwd").find("symbolic link"), std::string::npos);
  const std::string dotdot = read_error(t.root(), "../" + fs::path(outside.root()).filename().string() + "/secret.png");
  EXPECT_EQ(dotdot.rfind("stick file '../", 0), 0u) << dotdot;
  EXPECT_NE(dotdot.find("'..'"), std::string::npos) << dotdot;
  EXPECT_NE(read_error(t.root(), "sub/../apple.jpg").find("'..'"), std::string::npos);
  EXPECT_NE(read_error(t.root(), "/etc/passwd").find("absolute"), std::string::npos);
  EXPECT_NE(read_error(t.root(), "sub//x").find("empty"), std::string::npos);
  EXPECT_NE(read_error(t.root(), "").find("empty"), std::string::npos);
  EXPECT_NE(read_error(t.root(), "nothing.png").find("no such file"), std::string::npos);
  EXPECT_NE(read_error(t.root(), "sub").find("a folder"), std::string::npos);
  EXPECT_EQ(read_error(t.root(), "apple.jpg"), "");
}

TEST(StickScan, FifoAndSocketAreRefusedWithoutBlocking) {
  TempTree t;
  t.write("horse.png", tiny_png());
  ASSERT_EQ(::mkfifo((t / "pipe.png").c_str(), 0644), 0) << std::strerror(errno);
  const int sock = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(sock, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  const std::string sock_path = t / "sock.png";
  ASSERT_LT(sock_path.size(), sizeof addr.sun_path);
  std::memcpy(addr.sun_path, sock_path.c_str(), sock_path.size() + 1);
  ASSERT_EQ(::bind(sock, reinterpret_cast<const sockaddr*>(&addr), sizeof addr), 0) << std::strerror(errno);
  const ScanLimits limits;
  const StickScan s = scan_stick(t.root(), limits);  // would hang here if the FIFO were opened for reading
  ::close(sock);
  expect_well_formed(s, limits);
  EXPECT_EQ(doc_paths(s), std::vector<std::string>{"horse.png"});
  EXPECT_EQ(refusal(s, "pipe.png"), "a named pipe (FIFO), not a file");
  EXPECT_EQ(refusal(s, "sock.png"), "a socket, not a file");
  // Asked for directly (a FIFO swapped in after a scan), it is refused, and the open does not block.
  const std::string e = read_error(t.root(), "pipe.png");
  EXPECT_EQ(e, "stick file 'pipe.png': a named pipe (FIFO), not a file");
  EXPECT_NE(read_error(t.root(), "sock.png"), "");
}

TEST(StickScan, DeviceNodesAreRefused) {
  TempTree t;
  if (::mknod((t / "zero.png").c_str(), S_IFCHR | 0644, makedev(1, 5)) != 0) {
    const int e = errno;
    if (e == EPERM || e == EACCES) GTEST_SKIP() << "mknod needs CAP_MKNOD here: " << std::strerror(e);
    FAIL() << "mknod: " << std::strerror(e);
  }
  ASSERT_EQ(::mknod((t / "disk").c_str(), S_IFBLK | 0600, makedev(7, 0)), 0) << std::strerror(errno);
  t.write("horse.png", tiny_png());
  const ScanLimits limits;
  const StickScan s = scan_stick(t.root(), limits);
  expect_well_formed(s, limits);
  EXPECT_EQ(doc_paths(s), std::vector<std::string>{"horse.png"});
  EXPECT_EQ(refusal(s, "zero.png"), "a device node, not a file");
  EXPECT_EQ(refusal(s, "disk"), "a device node, not a file");
  const std::string e = read_error(t.root(), "zero.png");
  EXPECT_NE(e.find("device node"), std::string::npos) << e;
}

TEST(StickScan, FoldersDeeperThanTheLimitAreNotEntered) {
  TempTree t;
  std::string rel;
  t.write("p.png", tiny_png());
  for (int depth = 1; depth <= 50; ++depth) {
    rel += (depth > 1 ? "/" : "") + std::string("d");
    t.write(rel + "/p.png", tiny_png());
  }
  const ScanLimits limits;  // max_depth 8
  const StickScan s = scan_stick(t.root(), limits);
  expect_well_formed(s, limits);
  EXPECT_TRUE(s.complete);
  std::vector<std::string> want{"p.png"};
  std::string folder;
  for (int depth = 1; depth <= 8; ++depth) {
    folder += (depth > 1 ? "/" : "") + std::string("d");
    want.push_back(folder + "/p.png");
  }
  std::sort(want.begin(), want.end());
  EXPECT_EQ(doc_paths(s), want);
  EXPECT_EQ(refusal(s, folder + "/d"), "folder deeper than 8 levels is not entered");
  EXPECT_EQ(s.refused.size(), 1u);
  EXPECT_EQ(s.entries_scanned, 1 + 8 * 2 + 1);  // root: p.png, d; 8 folders: p.png, d (the 9th d refused)
  ScanLimits shallow;
  shallow.max_depth = 2;
  const StickScan s2 = scan_stick(t.root(), shallow);
  EXPECT_EQ(doc_paths(s2), (std::vector<std::string>{"d/d/p.png", "d/p.png", "p.png"}));
  EXPECT_EQ(refusal(s2, "d/d/d"), "folder deeper than 2 levels is not entered");
}

TEST(StickScan, EntryLimitStopsAFloodOfFiles) {
  TempTree t;
  t.mkdir("flood");
  for (int i = 0; i < 100000; ++i) {
    const std::string p = t / ("flood/f" + std::to_string(i));
    const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
    ASSERT_GE(fd, 0) << std::strerror(errno);
    ::close(fd);
  }
  t.write("zz/late.png", tiny_png());  // after "flood" in name order: never reached
  const ScanLimits limits;             // max_entries 10 000
  const StickScan s = scan_stick(t.root(), limits);
  expect_well_formed(s, limits);
  EXPECT_FALSE(s.complete);
  EXPECT_NE(s.stopped_by.find("entry limit"), std::string::npos) << s.stopped_by;
  EXPECT_NE(s.stopped_by.find("10000"), std::string::npos) << s.stopped_by;
  EXPECT_EQ(s.entries_scanned, limits.max_entries);  // never more than the limit
  EXPECT_TRUE(s.documents.empty());
  // The entries looked at are still classified (empty files); nothing beyond them.
  // flood, zz, then 9 998 of flood's files: those files refused as empty, zz unentered, and the stop line.
  EXPECT_EQ(s.refused.size(), static_cast<std::size_t>(limits.max_entries - 2 + 2));
  EXPECT_EQ(refusal(s, "zz"), "folder not entered: the limit of 10000 entries was reached");
  for (std::size_t i = 0; i + 1 < s.refused.size(); ++i) {
    if (s.refused[i].path == "zz") continue;
    ASSERT_EQ(s.refused[i].reason, "empty file (0 bytes)") << s.refused[i].path;
  }
}

TEST(StickScan, DocumentLimitCapsTheList) {
  TempTree t;
  for (int i = 0; i < 30; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "Bilder/p%02d.png", i);
    t.write(name, tiny_png());
  }
  ScanLimits limits;
  limits.max_documents = 10;
  const StickScan s = scan_stick(t.root(), limits);
  expect_well_formed(s, limits);
  EXPECT_FALSE(s.complete);
  EXPECT_NE(s.stopped_by.find("document limit"), std::string::npos) << s.stopped_by;
  ASSERT_EQ(s.documents.size(), 10u);
  EXPECT_EQ(s.documents.front().path, "Bilder/p00.png");  // the first ten in name order
  EXPECT_EQ(s.documents.back().path, "Bilder/p09.png");
  EXPECT_EQ(refusal(s, "Bilder/p10.png"), "over the limit of 10 documents");
  EXPECT_EQ(refusal(s, "Bilder/p11.png"), "");  // the walk stopped there
}

TEST(StickScan, EmptyMislabelledAndOversizedFilesAreRefused) {
  TempTree t;
  t.write("empty.pdf", "");
  t.write("text.pdf", "Dies ist kein PDF.\n");
  t.write("ok.png", tiny_png());
  // A sparse 250 MB "PNG": magic bytes at offset 0, the rest a hole (nothing is written to disk).
  {
    const int fd = ::open((t / "big.png").c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::write(fd, kPngMagic.data(), kPngMagic.size()), static_cast<ssize_t>(kPngMagic.size()));
    ASSERT_EQ(::ftruncate(fd, 262144000), 0) << std::strerror(errno);
    ::close(fd);
  }
  t.write("medium.pdf", "%PDF-1.4\n" + std::string(5000, ' '));
  const ScanLimits limits;  // 200 MB
  const StickScan s = scan_stick(t.root(), limits);
  expect_well_formed(s, limits);
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(doc_paths(s), (std::vector<std::string>{"medium.pdf", "ok.png"}));
  EXPECT_EQ(refusal(s, "empty.pdf"), "empty file (0 bytes)");
  EXPECT_EQ(refusal(s, "text.pdf"), "not a picture or PDF (unknown format)");
  EXPECT_EQ(refusal(s, "big.png"), "file size 262144000 bytes exceeds the limit of 209715200 bytes");
  ScanLimits small;
  small.max_file_bytes = 1000;
  const StickScan s2 = scan_stick(t.root(), small);
  EXPECT_EQ(doc_paths(s2), std::vector<std::string>{"ok.png"});
  EXPECT_EQ(refusal(s2, "medium.pdf"), "file size 5009 bytes exceeds the limit of 1000 bytes");
  // read_stick_file applies its own limit.
  EXPECT_EQ(read_error(t.root(), "big.png", 209715200),
            "stick file 'big.png': file size 262144000 bytes exceeds the limit of 209715200 bytes");
  EXPECT_EQ(read_error(t.root(), "medium.pdf", 1000),
            "stick file 'medium.pdf': file size 5009 bytes exceeds the limit of 1000 bytes");
  EXPECT_EQ(read_error(t.root(), "medium.pdf", 5009), "");
  EXPECT_NE(read_error(t.root(), "ok.png", 0).find("not positive"), std::string::npos);
}

// With picture_check = image_header_problem (as at the kiosk), a picture whose header cannot be read (real bad files
// from tests/data/bad: a PNG whose IHDR checksum is wrong, an empty PNG, a PNG whose image data is damaged but header
// whole) is refused at the scan, as a document, with the header parser's one line; a whole picture is listed. Without
// it, the magic bytes alone decide.
TEST(StickScan, PicturesWhoseHeaderCannotBeReadAreRefusedAsDocuments) {
  TempTree t;
  const std::string bad = std::string(HK_TEST_DATA_DIR) + "/bad/";
  const auto copy = [&](const std::string& from, const std::string& to) {
    std::ifstream in(from, std::ios::binary);
    t.write(to, std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
  };
  copy(bad + "bad_crc.png", "bad_crc.png");
  copy(bad + "damaged_idat.png", "damaged_idat.png");
  copy(std::string(HK_TEST_DATA_DIR) + "/images/horse.png", "horse.png");
  ScanLimits limits;
  limits.picture_check = image_header_problem;
  const StickScan s = scan_stick(t.root(), limits);
  expect_well_formed(s, limits);
  EXPECT_EQ(doc_paths(s), (std::vector<std::string>{"damaged_idat.png", "horse.png"}))
      << "a whole header is listed; its pixels are read when shown";
  EXPECT_NE(refusal(s, "bad_crc.png").find("CRC"), std::string::npos) << refusal(s, "bad_crc.png");
  ASSERT_EQ(s.refused.size(), 1u);
  EXPECT_TRUE(s.refused[0].document);
  EXPECT_EQ(s.refused[0].reason.find('\n'), std::string::npos);
  const StickScan plain = scan_stick(t.root(), ScanLimits{});
  EXPECT_EQ(doc_paths(plain), (std::vector<std::string>{"bad_crc.png", "damaged_idat.png", "horse.png"}));
}

TEST(StickScan, HostileNamesAreShownSafelyAndStillOpen) {
  TempTree t;
  const std::string cafe = "caf\xe9.png";                // Latin-1, not UTF-8
  const std::string rlo = "photo\xE2\x80\xAEgnp.exe";    // shows as "photoexe.png" with the override
  const std::string lines = "line\nbreak\r\x1b[2J.png";  // newline, CR, terminal escape
  const std::string folder =
      "\xff\xfe\xE2\x80\x8B"
      "Ordner";  // invalid bytes and a zero-width space
  std::string long_name;
  for (int i = 0; i < 85; ++i) long_name += "\xE6\x97\xA5";  // 255 bytes, the longest name
  t.write(cafe, tiny_png());
  t.write(rlo, tiny_png());
  t.write(lines, tiny_png());
  t.write(folder + "/x\x01y.png", tiny_png());
  t.write(long_name + "/" + long_name, tiny_png());
  t.write("bad\nname.txt", "text");
  const ScanLimits limits;
  const StickScan s = scan_stick(t.root(), limits);
  expect_well_formed(s, limits);  // every display name and refusal: valid UTF-8, one line, no controls
  ASSERT_EQ(s.documents.size(), 5u);
  const std::string fffd = "\xEF\xBF\xBD";
  EXPECT_EQ(find_doc(s, cafe)->display_name, "caf" + fffd + ".png");
  EXPECT_EQ(find_doc(s, rlo)->display_name, "photognp.exe");
  EXPECT_EQ(find_doc(s, lines)->display_name, "linebreak[2J.png");
  EXPECT_EQ(find_doc(s, folder + "/x\x01y.png")->display_name, fffd + fffd + "Ordner/xy.png");
  const StickDocument* lng = find_doc(s, long_name + "/" + long_name);
  ASSERT_NE(lng, nullptr);
  EXPECT_LE(lng->display_name.size(), 255u);
  EXPECT_EQ(lng->display_name, long_name.substr(0, 252) + "\xE2\x80\xA6");  // 511 bytes → 84 characters and "…"
  EXPECT_EQ(lng->display_name.substr(lng->display_name.size() - 3), "\xE2\x80\xA6");
  EXPECT_EQ(refusal(s, "badname.txt"), "not a picture or PDF (unknown format)");
  // The raw path still opens the file.
  for (const auto& d : s.documents)
    EXPECT_EQ(read_stick_file(t.root(), d.path, limits.max_file_bytes).size(), tiny_png().size()) << d.display_name;
  // A refused read names the file safely too, on one line.
  const std::string e = read_error(t.root(), lines + ".missing");
  EXPECT_EQ(e, "stick file 'linebreak[2J.png.missing': no such file");
}

TEST(StickScan, TimeLimitStopsTheWalk) {
  TempTree t;
  for (int i = 0; i < 3000; ++i) t.write("f" + std::to_string(i / 100) + "/p" + std::to_string(i) + ".png", tiny_png());
  ScanLimits limits;
  limits.max_seconds = 1e-6;
  const StickScan s = scan_stick(t.root(), limits);
  expect_well_formed(s, limits);
  EXPECT_FALSE(s.complete);
  EXPECT_NE(s.stopped_by.find("time limit"), std::string::npos) << s.stopped_by;
  EXPECT_LT(s.documents.size(), 3000u);
}

TEST(StickScan, FileSwappedAfterTheScanIsRefusedOnRead) {
  TempTree t, outside;
  outside.copy("images/butterfly.jpg", "butterfly.jpg");
  t.copy("images/horse.png", "horse.png");
  t.copy("images/apple.jpg", "Fotos/apple.jpg");
  t.copy("images/coins.png", "coins.png");
  const ScanLimits limits;
  const StickScan s = scan_stick(t.root(), limits);
  ASSERT_EQ(doc_paths(s), (std::vector<std::string>{"Fotos/apple.jpg", "coins.png", "horse.png"}));
  // File → link to a system file.
  ASSERT_EQ(::unlink((t / "horse.png").c_str()), 0);
  t.symlink("/etc/passwd", "horse.png");
  EXPECT_EQ(read_error(t.root(), "horse.png"), "stick file 'horse.png': a symbolic link (links are not followed)");
  // Folder → link to a folder outside with a file of the same name.
  fs::remove_all(t / "Fotos");
  ASSERT_EQ(::rename((outside / "butterfly.jpg").c_str(), (outside / "apple.jpg").c_str()), 0);
  t.symlink(outside.root(), "Fotos");
  EXPECT_NE(read_error(t.root(), "Fotos/apple.jpg").find("symbolic link"), std::string::npos);
  // File → FIFO: refused, without blocking.
  ASSERT_EQ(::unlink((t / "coins.png").c_str()), 0);
  ASSERT_EQ(::mkfifo((t / "coins.png").c_str(), 0644), 0);
  EXPECT_EQ(read_error(t.root(), "coins.png"), "stick file 'coins.png': a named pipe (FIFO), not a file");
}

TEST(StickScan, MountPointsInsideTheStickAreNotEntered) {
  TempTree t;
  t.write("horse.png", tiny_png());
  t.mkdir("mnt");
  if (::mount("tmpfs", (t / "mnt").c_str(), "tmpfs", MS_NOSUID | MS_NODEV | MS_NOEXEC, "size=1m") != 0) {
    GTEST_SKIP() << "cannot mount a tmpfs here: " << std::strerror(errno);
  }
  { std::ofstream(t / "mnt/inner.png", std::ios::binary) << tiny_png(); }
  const ScanLimits limits;
  const StickScan s = scan_stick(t.root(), limits);
  const std::string read = read_error(t.root(), "mnt/inner.png");
  ::umount2((t / "mnt").c_str(), MNT_DETACH);
  expect_well_formed(s, limits);
  EXPECT_EQ(doc_paths(s), std::vector<std::string>{"horse.png"});
  EXPECT_EQ(refusal(s, "mnt"), "on another filesystem (mount points are not entered)");
  EXPECT_NE(read.find("another filesystem"), std::string::npos) << read;
}

TEST(StickScan, ScanAndReadChangeNothing) {
  TempTree t, outside;
  outside.copy("images/horse.png", "secret.png");
  t.copy("images/horse.png", "horse.png");
  t.copy("images/fruits.jpg", "a/b/fruits.jpg");
  t.copy("documents/horse_and_page.pdf", "a/doc.pdf");
  t.write("a/empty.pdf", "");
  t.write("a/._x.png", tiny_png());
  t.symlink(outside / "secret.png", "a/link.png");
  ASSERT_EQ(::mkfifo((t / "a/pipe").c_str(), 0644), 0);
  const auto before = listing(t.root());
  const auto outside_before = listing(outside.root());
  const ScanLimits limits;
  const StickScan s = scan_stick(t.root(), limits);
  ASSERT_EQ(s.documents.size(), 3u);
  for (const auto& d : s.documents) (void)read_stick_file(t.root(), d.path, limits.max_file_bytes);
  (void)scan_stick(t.root(), limits);
  EXPECT_EQ(listing(t.root()), before);
  EXPECT_EQ(listing(outside.root()), outside_before);
}

TEST(StickScan, BadRootOrLimitsAreTypedOneLineErrors) {
  TempTree t;
  t.write("file.png", tiny_png());
  const ScanLimits ok;
  try {
    (void)scan_stick(t / "missing", ok);
    FAIL() << "no error for a missing root";
  } catch (const StickError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("stick '", 0), 0u) << m;
    EXPECT_NE(m.find("No such file"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos);
  }
  try {
    (void)scan_stick(t / "file.png", ok);
    FAIL() << "no error for a file as root";
  } catch (const StickError& e) {
    EXPECT_NE(std::string(e.what()).find("not a folder"), std::string::npos) << e.what();
  }
  auto with = [&](auto change) {
    ScanLimits l;
    change(l);
    return l;
  };
  EXPECT_THROW((void)scan_stick(t.root(), with([](ScanLimits& l) { l.max_depth = 0; })), hk::ArgumentError);
  EXPECT_THROW((void)scan_stick(t.root(), with([](ScanLimits& l) { l.max_entries = -1; })), hk::ArgumentError);
  EXPECT_THROW((void)scan_stick(t.root(), with([](ScanLimits& l) { l.max_documents = 0; })), hk::ArgumentError);
  EXPECT_THROW((void)scan_stick(t.root(), with([](ScanLimits& l) { l.max_file_bytes = 0; })), hk::ArgumentError);
  EXPECT_THROW((void)scan_stick(t.root(), with([](ScanLimits& l) { l.max_seconds = 0.0; })), hk::ArgumentError);
  EXPECT_THROW((void)scan_stick(t.root(), with([](ScanLimits& l) { l.max_seconds = std::nan(""); })),
               hk::ArgumentError);
  EXPECT_NE(read_error(t / "missing", "file.png").find("stick file 'file.png'"), std::string::npos);
}

}  // namespace
}  // namespace hk::vision
