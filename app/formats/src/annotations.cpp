// W3C Web Annotation files as IIIF publishes them, read and written (annotations.hpp).
#include "formats/annotations.hpp"

#include <nlohmann/json.hpp>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "hk/language.hpp"
#include "hk/text.hpp"

namespace hk::app {
namespace {

using json = nlohmann::json;

/// The string at `key` of object `j`, or "" when absent or not a string.
std::string str(const json& j, const char* key) {
  if (!j.is_object()) return {};
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

/// A value that may be one item or an array of them, as an array of pointers into `j`.
std::vector<const json*> items_of(const json& j) {
  std::vector<const json*> out;
  if (j.is_array()) {
    for (const json& e : j) out.push_back(&e);
  } else if (!j.is_null()) {
    out.push_back(&j);
  }
  return out;
}

/// items_of the value at `key` of object `j`; empty when `j` has none.
std::vector<const json*> items_at(const json& j, const char* key) {
  if (!j.is_object()) return {};
  const auto it = j.find(key);
  return it == j.end() ? std::vector<const json*>{} : items_of(*it);
}

/// The `type` of an object: "type", else "@type"; a Presentation 2 prefix ("oa:", "sc:", "dctypes:") dropped.
std::string type_of(const json& j) {
  std::string t = str(j, "type");
  if (t.empty()) t = str(j, "@type");
  const std::size_t colon = t.find(':');
  return colon == std::string::npos ? t : t.substr(colon + 1);
}

/// A motivation or purpose without its "oa:" prefix.
std::string bare(std::string v) { return v.rfind("oa:", 0) == 0 ? v.substr(3) : v; }

/// Why `text` is no good as a name (lines false) or description (lines true) of at most `max` bytes; "" when fine.
std::string text_problem(const std::string& text, std::size_t max, bool lines, const std::string& what) {
  if (text.size() > max) return "the " + what + " is longer than " + std::to_string(max) + " bytes";
  for (std::size_t i = 0; i < text.size();) {
    const Utf8Step st = decode_utf8(text, i);
    if (!st.well_formed) return "the " + what + " is not valid UTF-8";
    const char32_t c = st.code_point;
    if ((c < 0x20 && !(lines && (c == '\n' || c == '\t'))) || (c >= 0x7F && c <= 0x9F))
      return "the " + what + " has a control character";
    i += st.length;
  }
  return {};
}

/// Whether an HTML tag (its text between < and >) breaks a line: p, br, div, li, h1-h6, tr, td (opening or closing).
bool breaks_line(std::string tag) {
  if (!tag.empty() && tag[0] == '/') tag.erase(0, 1);
  std::string name;
  for (const char ch : tag) {
    if (!std::isalnum(static_cast<unsigned char>(ch))) break;
    name += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  }
  for (const char* b : {"p", "br", "div", "li", "h1", "h2", "h3", "h4", "h5", "h6", "tr", "td"})
    if (name == b) return true;
  return false;
}

/// Text with HTML tags taken out (a block tag is a space) and white space folded (Presentation 2 `chars` are
/// often "<p>…</p>").
std::string plain_text(const std::string& html) {
  std::string out, tag;
  bool in_tag = false, space = false;
  for (const char ch : html) {
    if (in_tag) {
      if (ch != '>') {
        tag += ch;
        continue;
      }
      in_tag = false;
      space = space || (breaks_line(tag) && !out.empty());
      continue;
    }
    if (ch == '<') {
      in_tag = true;
      tag.clear();
      continue;
    }
    if (ch == ' ' || ch == '\n' || ch == '\r' || ch == '\t') {
      space = !out.empty();
      continue;
    }
    if (space) out += ' ';
    space = false;
    out += ch;
  }
  return out;
}

/// Parses "xywh=[pixel:|percent:]x,y,w,h" (the media fragment of a URL or a FragmentSelector's value).
bool parse_xywh(std::string v, AnnotationSelector* out) {
  const std::size_t at = v.find("xywh=");
  if (at == std::string::npos) return false;
  v = v.substr(at + 5);
  AnnotationSelector s;
  if (v.rfind("percent:", 0) == 0) {
    s.percent = true;
    v = v.substr(8);
  } else if (v.rfind("pixel:", 0) == 0) {
    v = v.substr(6);
  }
  double n[4];
  std::istringstream in(v);
  char comma = 0;
  for (int i = 0; i < 4; ++i) {
    if (!(in >> n[i]) || !std::isfinite(n[i])) return false;
    if (i < 3 && (!(in >> comma) || comma != ',')) return false;
  }
  s.x = n[0];
  s.y = n[1];
  s.w = n[2];
  s.h = n[3];
  *out = s;
  return true;
}

/// A selector object (FragmentSelector, SvgSelector, a Presentation 2 oa:Choice of two); false when none of these.
bool parse_selector(const json& sel, AnnotationSelector* out) {
  const std::string t = type_of(sel);
  if (t == "FragmentSelector") return parse_xywh(str(sel, "value"), out);
  if (t == "SvgSelector") {
    out->kind = AnnotationSelector::Kind::svg;
    out->svg = str(sel, "value");
    return !out->svg.empty();
  }
  if (t == "Choice") {  // Presentation 2 (Mirador 2): the SVG shape when there is one, else the box
    for (const char* key : {"item", "default"}) {
      const auto it = sel.find(key);
      if (it != sel.end() && parse_selector(*it, out)) return true;
    }
    return false;
  }
  return false;
}

/// The region a target names: a "source#xywh=…" string, or a SpecificResource with a selector.
bool parse_target(const json& target, AnnotationSelector* out) {
  for (const json* t : items_of(target)) {
    if (t->is_string()) {
      if (parse_xywh(t->get<std::string>(), out)) return true;
      continue;
    }
    for (const json* s : items_at(*t, "selector"))
      if (parse_selector(*s, out)) return true;
    const std::string id = str(*t, "id").empty() ? str(*t, "@id") : str(*t, "id");
    if (parse_xywh(id, out)) return true;  // {"id": "canvas#xywh=…", "type": "Canvas"}
  }
  return false;
}

/// The name and description of an annotation's bodies: the first name's language is the annotation's, a body
/// tagged with another language a translation (the first of each kind a language kept).
struct Texts {
  std::string name, description, language;
  std::map<std::string, Annotation::Translation> translations;
};

Texts bodies_of(const json& a, const std::string& motivation) {
  Texts t;
  bool named = false;
  for (const json* b : a.contains("body") ? items_at(a, "body") : items_at(a, "resource")) {
    std::string value = b->is_string() ? b->get<std::string>() : str(*b, "value");
    if (value.empty()) value = plain_text(str(*b, "chars"));
    if (value.empty()) continue;
    std::string purpose = bare(str(*b, "purpose"));
    if (type_of(*b) == "Tag") purpose = "tagging";
    if (purpose.empty()) purpose = motivation;
    const bool describes = purpose == "describing" || purpose == "commenting";
    const std::string language = b->is_object() ? str(*b, "language") : std::string();
    if (!describes && !named) {
      named = true;
      t.name = value;
      t.language = language;
    }
    const bool own = language.empty() || language == t.language || (!named && describes);
    std::string& field = own ? (describes ? t.description : t.name)
                             : (describes ? t.translations[language].description : t.translations[language].name);
    if (field.empty()) field = value;
  }
  t.translations.erase(t.language);  // a description in the name's language, read before the name
  return t;
}

/// The motivation that says what an annotation's bodies are: identifying, tagging, describing or commenting
/// (the first of these in a list), else its first.
std::string motivation_of(const json& a) {
  std::string first;
  for (const json* m : items_at(a, "motivation")) {
    if (!m->is_string()) continue;
    const std::string v = bare(m->get<std::string>());
    if (v == "identifying" || v == "tagging" || v == "describing" || v == "commenting") return v;
    if (first.empty()) first = v;
  }
  return first;
}

class Reader {
 public:
  Reader(std::string source, std::string picture) : source_(std::move(source)), picture_(std::move(picture)) {}

  AnnotationSet read(const json& root) {
    if (root.is_array()) {
      add_all(root);
    } else if (!root.is_object()) {
      refuse("it is not an annotation, a list of them, an AnnotationPage, a Manifest or an sc:AnnotationList");
    } else {
      const std::string t = type_of(root);
      if (t == "AnnotationPage" || t == "AnnotationList") {
        add_page(root);
      } else if (t == "Annotation") {
        add(root);
      } else if (t == "Manifest") {
        add_manifest(root);
      } else {
        refuse("its type '" + one_line(t, 40) + "' is not Annotation, AnnotationPage, Manifest or sc:AnnotationList");
      }
    }
    return std::move(set_);
  }

 private:
  [[noreturn]] void refuse(const std::string& why) { throw AnnotationError(hk::quoted(source_) + ": " + why); }
  void problem(const std::string& why) { set_.problems.push_back(hk::quoted(source_) + ": " + why); }

  void add_all(const json& list) {
    for (const json& a : list) add(a);
  }

  void add_page(const json& page) {
    const auto list = page.find(page.contains("items") ? "items" : "resources");
    if (list == page.end() || !list->is_array()) {
      const std::string id = str(page, "id").empty() ? str(page, "@id") : str(page, "id");
      problem("the annotation page " + hk::quoted(id, 120) + " is only referenced, not included; it is not fetched");
      return;
    }
    add_all(*list);
  }

  void add_manifest(const json& m) {
    const auto items = m.find("items");
    if (items == m.end() || !items->is_array() || items->empty()) refuse("the Manifest has no canvas");
    const json& canvases = *items;
    const json* chosen = &canvases[0];
    for (const json& c : canvases)
      if (paints_picture(c)) {
        chosen = &c;
        break;
      }
    const json& c = *chosen;
    if (c.contains("width") && c["width"].is_number() && c.contains("height") && c["height"].is_number()) {
      set_.canvas_width_px = c["width"].get<double>();
      set_.canvas_height_px = c["height"].get<double>();
      if (!(set_.canvas_width_px > 0) || !(set_.canvas_height_px > 0)) refuse("the canvas has no positive size");
    }
    for (const json* page : items_at(c, "annotations")) add_page(*page);
  }

  /// Whether canvas `c` paints an image whose file name is the picture's.
  bool paints_picture(const json& c) const {
    if (picture_.empty() || !c.contains("items")) return false;
    for (const json* page : items_at(c, "items"))
      for (const json* a : items_at(*page, "items"))
        for (const json* b : items_at(*a, "body")) {
          const std::string id = str(*b, "id");
          const std::size_t slash = id.find_last_of('/');
          if (!id.empty() && id.substr(slash == std::string::npos ? 0 : slash + 1) == picture_) return true;
        }
    return false;
  }

  void add(const json& a) {
    const std::size_t n = ++seen_;
    if (set_.annotations.size() >= kMaxAnnotations) {
      if (n == kMaxAnnotations + 1)
        problem("more than " + std::to_string(kMaxAnnotations) + " annotations; the rest are left out");
      return;
    }
    const std::string which = "annotation " + std::to_string(n) + ": ";
    if (!a.is_object()) return problem(which + "it is not an object");
    const std::string motivation = motivation_of(a);
    if (motivation == "painting") return;  // the picture itself
    Annotation out;
    const Texts t = bodies_of(a, motivation);
    out.name = t.name;
    out.description = t.description;
    out.language = t.language;
    out.translations = t.translations;
    if (out.name.empty() && out.description.empty()) return problem(which + "it has no text body");
    for (const std::string& why : {text_problem(out.name, kMaxNameBytes, false, "name"),
                                   text_problem(out.description, kMaxRegionDescriptionBytes, true, "description")})
      if (!why.empty()) return problem(which + why);
    for (auto it = out.translations.begin(); it != out.translations.end();) {
      if (hk::is_language_tag(it->first)) {
        ++it;
        continue;
      }
      problem(which + "its language " + hk::quoted(it->first, 40) + " is not a BCP 47 tag; that text is left out");
      it = out.translations.erase(it);
    }
    for (const auto& [tag, tr] : out.translations)
      for (const std::string& why :
           {text_problem(tr.name, kMaxNameBytes, false, "name in " + tag),
            text_problem(tr.description, kMaxRegionDescriptionBytes, true, "description in " + tag)})
        if (!why.empty()) return problem(which + why);
    const auto target = a.find(a.contains("target") ? "target" : "on");
    if (target == a.end() || !parse_target(*target, &out.selector))
      return problem(which + "its target has no FragmentSelector (xywh=) or SvgSelector");
    if (set_.canvas_width_px <= 0) canvas_of_source(*target);
    const AnnotationSelector& s = out.selector;
    if (s.kind == AnnotationSelector::Kind::svg && s.svg.size() > kMaxSvgBytes)
      return problem(which + "its SVG selector is larger than " + std::to_string(kMaxSvgBytes / 1024) + " kB");
    if (s.kind == AnnotationSelector::Kind::rect && !(s.w > 0 && s.h > 0))
      return problem(which + "its region has no positive width and height");
    set_.annotations.push_back(std::move(out));
  }

  /// A target whose source is a Canvas with its size (as write_annotation_page writes one): the canvas the
  /// coordinates are in, when no Manifest said it.
  void canvas_of_source(const json& target) {
    if (!target.is_object()) return;
    const auto src = target.find("source");
    if (src == target.end() || !src->is_object() || type_of(*src) != "Canvas") return;
    const auto w = src->find("width"), h = src->find("height");
    if (w == src->end() || h == src->end() || !w->is_number() || !h->is_number()) return;
    if (!(w->get<double>() > 0) || !(h->get<double>() > 0)) return;
    set_.canvas_width_px = w->get<double>();
    set_.canvas_height_px = h->get<double>();
  }

  std::string source_, picture_;
  AnnotationSet set_;
  std::size_t seen_ = 0;
};

}  // namespace

Annotation::Translation annotation_text_in(const Annotation& a, std::string_view language, std::string* language_out) {
  Annotation::Translation out{a.name, a.description};
  if (language_out) *language_out = a.language;
  auto it = a.translations.find(std::string(language));
  if (it == a.translations.end()) it = a.translations.find(std::string(hk::language_subtag(language)));
  if (it == a.translations.end()) return out;
  if (!it->second.name.empty()) {
    out.name = it->second.name;
    if (language_out) *language_out = it->first;
  }
  if (!it->second.description.empty()) out.description = it->second.description;
  return out;
}

std::string annotation_text_problem(const std::string& text, bool description) {
  return description ? text_problem(text, kMaxRegionDescriptionBytes, true, "description")
                     : text_problem(text, kMaxNameBytes, false, "name");
}

std::string annotations_path(const std::string& picture_path) {
  std::filesystem::path p(picture_path);
  p.replace_extension(".annotations.json");
  return p.string();
}

std::string annotations_path_in(const std::string& names_dir, const std::string& picture_path) {
  return (std::filesystem::path(names_dir) / std::filesystem::path(annotations_path(picture_path)).filename()).string();
}

AnnotationSet parse_annotations(std::string_view text, const std::string& source,
                                const std::string& picture_file_name) {
  if (text.size() > kMaxAnnotationFileBytes)
    throw AnnotationError(hk::quoted(source) + ": larger than " + std::to_string(kMaxAnnotationFileBytes >> 20) +
                          " MB");
  const json root = json::parse(text.begin(), text.end(), nullptr, false);
  if (root.is_discarded()) throw AnnotationError(hk::quoted(source) + ": not JSON");
  return Reader(source, picture_file_name).read(root);
}

AnnotationSet read_annotations(const std::string& path, const std::string& picture_file_name) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw AnnotationError(hk::quoted(path) + ": cannot be read (" + ec.message() + ")");
  if (size > kMaxAnnotationFileBytes)
    throw AnnotationError(hk::quoted(path) + ": larger than " + std::to_string(kMaxAnnotationFileBytes >> 20) + " MB");
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw AnnotationError(hk::quoted(path) + ": cannot be read");
  return parse_annotations(text, path, picture_file_name);
}

std::string write_annotation_page(const AnnotationSet& set, const std::string& source) {
  json items = json::array();
  int n = 0;
  for (const Annotation& a : set.annotations) {
    json body = json::array();
    if (!a.name.empty()) {
      json b = {{"type", "TextualBody"}, {"value", a.name}, {"purpose", "identifying"}, {"format", "text/plain"}};
      if (!a.language.empty()) b["language"] = a.language;
      body.push_back(std::move(b));
    }
    if (!a.description.empty())
      body.push_back({{"type", "TextualBody"}, {"value", a.description}, {"purpose", "describing"}});
    for (const auto& [tag, tr] : a.translations) {  // one body a language and kind, tagged
      if (!tr.name.empty())
        body.push_back({{"type", "TextualBody"}, {"value", tr.name}, {"purpose", "identifying"}, {"language", tag}});
      if (!tr.description.empty())
        body.push_back(
            {{"type", "TextualBody"}, {"value", tr.description}, {"purpose", "describing"}, {"language", tag}});
    }
    json selector;
    if (a.selector.kind == AnnotationSelector::Kind::svg) {
      selector = {{"type", "SvgSelector"}, {"value", a.selector.svg}};
    } else {
      char v[160];
      std::snprintf(v, sizeof v, "xywh=%s%.10g,%.10g,%.10g,%.10g", a.selector.percent ? "percent:" : "", a.selector.x,
                    a.selector.y, a.selector.w, a.selector.h);
      selector = {{"type", "FragmentSelector"}, {"conformsTo", "http://www.w3.org/TR/media-frags/"}, {"value", v}};
    }
    json target_source = source;
    if (set.canvas_width_px > 0 && set.canvas_height_px > 0)  // coordinates on a canvas of its own size
      target_source = {
          {"id", source}, {"type", "Canvas"}, {"width", set.canvas_width_px}, {"height", set.canvas_height_px}};
    items.push_back(
        {{"id", "#name-" + std::to_string(++n)},
         {"type", "Annotation"},
         {"motivation", "identifying"},
         {"body", std::move(body)},
         {"target",
          {{"type", "SpecificResource"}, {"source", std::move(target_source)}, {"selector", std::move(selector)}}}});
  }
  const json page = {
      {"@context", "http://www.w3.org/ns/anno.jsonld"}, {"type", "AnnotationPage"}, {"items", std::move(items)}};
  return page.dump(2) + "\n";
}

}  // namespace hk::app
