// A gettext domain's MO file read with Boost.Locale (mo_catalogue.hpp).
#include "audio/mo_catalogue.hpp"

#include <boost/locale/gnu_gettext.hpp>
#include <boost/locale/message.hpp>

#include <fstream>
#include <iterator>
#include <locale>

#include "hk/language.hpp"
#include "hk/text.hpp"

namespace hk::audio {

std::string mo_problem(const std::vector<char>& mo) {
  const std::size_t size = mo.size();
  if (size < 28) return "shorter than an MO header";
  const auto u32 = [&](std::size_t at, bool swap) {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) {
      const auto byte = static_cast<std::uint32_t>(static_cast<unsigned char>(mo[at + static_cast<std::size_t>(i)]));
      v |= swap ? byte << (8 * (3 - i)) : byte << (8 * i);
    }
    return v;
  };
  bool swap = false;
  if (u32(0, false) != 0x950412deu) {
    if (u32(0, true) != 0x950412deu) return "no MO magic number";
    swap = true;
  }
  const std::uint64_t n = u32(8, swap), originals = u32(12, swap), translations = u32(16, swap);
  const std::uint64_t hash_size = u32(20, swap), hash_at = u32(24, swap);
  if ((u32(4, swap) >> 16) > 1) return "an MO revision this reader does not know";
  // Boost.Locale reads entry 0, the header (its Plural-Forms), whatever the count says: it must be there.
  if (n == 0) return "no header entry";
  for (const std::uint64_t table : {originals, translations}) {
    if (table + 8 * n > size) return "a string table runs past the end";
    for (std::uint64_t i = 0; i < n; ++i) {
      const std::uint64_t len = u32(static_cast<std::size_t>(table + 8 * i), swap);
      const std::uint64_t at = u32(static_cast<std::size_t>(table + 8 * i + 4), swap);
      if (at + len >= size || mo[static_cast<std::size_t>(at + len)] != '\0') return "a string runs past the end";
    }
  }
  if (hash_size > 0) {
    if (hash_at + 4 * hash_size > size) return "the hash table runs past the end";
    for (std::uint64_t i = 0; i < hash_size; ++i)
      if (u32(static_cast<std::size_t>(hash_at + 4 * i), swap) > n) return "a hash slot names no string";
  }
  return {};
}

struct MoCatalogue::Compiled {
  std::locale locale;  // owns the facet
  const boost::locale::message_format<char>* facet = nullptr;
  int domain = 0;
};

std::string MoCatalogue::where() const {
  return "catalogue '" + hk::one_line(language_) + "' (" + hk::one_line(source_) + "): ";
}

MoCatalogue MoCatalogue::from_bytes(std::string_view domain, std::string_view language, std::vector<char> mo_bytes,
                                    const std::string& source) {
  MoCatalogue c;
  c.language_ = language;
  c.source_ = source;
  const std::string where = c.where();
  if (!is_language_tag(language)) throw MessageError(where + "not a BCP 47 language tag such as \"fr\" or \"pt-BR\"");
  if (const std::string why = mo_problem(mo_bytes); !why.empty())
    throw MessageError(where + "not a gettext MO file (" + why + ")");
  namespace gg = boost::locale::gnu_gettext;
  gg::messages_info info;
  info.language = std::string(hk::language_subtag(language));
  info.encoding = "UTF-8";
  info.domains.emplace_back(std::string(domain));
  info.paths.emplace_back("memory");
  bool handed = false;
  info.callback = [&](const std::string&, const std::string&) {
    if (handed) return std::vector<char>();
    handed = true;
    return mo_bytes;
  };
  auto compiled = std::make_shared<Compiled>();
  try {
    boost::locale::message_format<char>* facet = gg::create_messages_facet<char>(info);
    if (!facet) throw MessageError(where + "Boost.Locale made no catalogue of it");
    compiled->locale = std::locale(std::locale::classic(), facet);
    compiled->facet = facet;
    compiled->domain = facet->domain(std::string(domain));
  } catch (const MessageError&) {
    throw;
  } catch (const std::exception& e) {
    throw MessageError(where + "not a gettext MO file (" + hk::one_line(e.what(), 120) + ")");
  }
  if (!handed) throw MessageError(where + "not read");
  c.compiled_ = std::move(compiled);
  return c;
}

MoCatalogue MoCatalogue::load(std::string_view domain, std::string_view language,
                              const std::filesystem::path& locale_dir) {
  const std::string shown = hk::one_line(std::string(language));
  if (!is_language_tag(language))
    throw MessageError("catalogue '" + shown + "': not a BCP 47 language tag such as \"fr\" or \"pt-BR\"");
  const std::string file_name = std::string(domain) + ".mo";
  std::filesystem::path file;
  for (const std::string_view tag : {language, hk::language_subtag(language)}) {
    const auto f = locale_dir / std::string(tag) / "LC_MESSAGES" / file_name;
    std::error_code ec;
    if (std::filesystem::is_regular_file(f, ec)) {
      file = f;
      break;
    }
  }
  if (file.empty())
    throw MessageError("catalogue '" + shown + "': no file " +
                       hk::one_line((locale_dir / std::string(language) / "LC_MESSAGES" / file_name).string()));
  const std::string where = "catalogue '" + shown + "' (" + hk::one_line(file.string()) + "): ";
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  if (ec) throw MessageError(where + "cannot read it");
  if (size > kMaxCatalogueBytes)
    throw MessageError(where + std::to_string(size) + " bytes is over the limit of " +
                       std::to_string(kMaxCatalogueBytes) + " bytes");
  std::ifstream in(file, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw MessageError(where + "cannot read it");
  return from_bytes(domain, language, std::move(bytes), file.string());
}

const char* MoCatalogue::get(const char* context, const char* id) const {
  return compiled_ ? compiled_->facet->get(compiled_->domain, context, id) : nullptr;
}

const char* MoCatalogue::get(const char* context, const char* id, int count) const {
  return compiled_ ? compiled_->facet->get(compiled_->domain, context, id, count) : nullptr;
}

}  // namespace hk::audio
