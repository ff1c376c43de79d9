// The Where and Describe answers (answers.hpp).
#include "visit/answers.hpp"

#include <algorithm>
#include <cctype>

#include <opencv2/imgproc.hpp>

#include "hk/language.hpp"
#include "hk/text.hpp"
#include "visit/describe.hpp"
#include "visit/read_aloud.hpp"

namespace hk::app {
namespace {

/// Whether `text` opens with `title` (letters compared without case, a trailing full stop of the title
/// ignored): a description that repeats its picture's title ("A horse, seen from the side." after "A horse").
bool opens_with(const std::string& text, std::string title) {
  while (!title.empty() && (title.back() == '.' || title.back() == ' ')) title.pop_back();
  if (title.empty() || text.size() < title.size()) return false;
  for (std::size_t i = 0; i < title.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(text[i])) != std::tolower(static_cast<unsigned char>(title[i])))
      return false;
  return true;
}

}  // namespace

std::string notes_words(const PictureNotes& notes) {
  std::string words;
  if (!notes.title.empty() && !opens_with(notes.description, notes.title)) {
    words = sentence_case(notes.title);
    if (words.back() != '.' && words.back() != '!' && words.back() != '?') words += '.';
    words += ' ';
  }
  if (!notes.description.empty()) words += notes.description + ' ';
  return words;
}

std::string region_said_name(const meaning::NamedRegion& region, const audio::MessageCatalog& m) {
  switch (region.source) {
    case meaning::RegionSource::staff:
      return said_name(meaning::region_name_in(region, m.language()), m);
    case meaning::RegionSource::face:
      return m.word("guess_face");
    case meaning::RegionSource::text: {
      constexpr std::string_view kLead = "text: ";  // as meaning::guessed_region names it
      const std::string words = region.name.rfind(kLead, 0) == 0 ? region.name.substr(kLead.size()) : region.name;
      return m.word("guess_text", 1, {{"text", words}});
    }
  }
  return region.name;
}

namespace {

/// What kind of name a region has, which decides how one of several shapes taking it is said.
enum class NameKind {
  proper,    ///< a proper name or a guess ("Pegasus", "text: Exit"): said as it is
  singular,  ///< "left wing": "part of the left wing"
  plural,    ///< "white spots": "one of the white spots"
};

/// The kind of `region`'s name, judged on its English name where it has one (the one language whose plurals
/// these rules know), else its own: every language's said form then takes the same one. A name in small letters
/// is a common noun; its head (before " of ") ending in "s" or "ae" a plural.
NameKind name_kind(const meaning::NamedRegion& region) {
  if (region.source != meaning::RegionSource::staff) return NameKind::proper;
  std::string language;
  std::string name = meaning::region_name_in(region, "en", &language);
  if (hk::language_subtag(language) != "en" && !language.empty()) name = region.name;
  for (const char* article : {"the ", "a ", "an "})
    if (name.rfind(article, 0) == 0) name = name.substr(std::string_view(article).size());
  const unsigned char c = name.empty() ? 'A' : static_cast<unsigned char>(name[0]);
  if (c < 0x80 && !std::islower(c)) return NameKind::proper;
  const std::string head = name.substr(0, name.find(" of "));  // "coins of the top row": "coins"
  return head.ends_with("s") || head.ends_with("ae") ? NameKind::plural : NameKind::singular;
}

/// Sets each part's curve: the longest of `polylines` whose region's name is said as the part's.
void longest_curve_of_each_part(const std::vector<meaning::NamedRegion>& regions, const std::vector<int>& shape_region,
                                const std::vector<Polyline>& polylines, PictureNames& names,
                                const audio::MessageCatalog& m) {
  std::vector<double> best(names.parts.size(), 0.0);
  for (std::size_t i = 0; i < polylines.size() && i < shape_region.size(); ++i) {
    if (shape_region[i] < 0) continue;
    const std::string name = region_said_name(regions[static_cast<std::size_t>(shape_region[i])], m);
    const double len = polyline_length_m(polylines[i]);
    for (std::size_t p = 0; p < names.parts.size(); ++p)
      if (names.parts[p].name == name && len > best[p]) {
        best[p] = len;
        names.parts[p].curve = static_cast<int>(i);
      }
  }
}

}  // namespace

PictureNames picture_names(const std::vector<meaning::NamedRegion>& regions, const std::vector<int>& shape_region,
                           std::size_t curves, const vision::PxToM& px_to_m, const std::vector<Polyline>* polylines,
                           const audio::MessageCatalog& m) {
  PictureNames out;
  if (regions.empty()) return out;
  out.shape_name.assign(curves, std::string());
  out.part_name.assign(curves, std::string());
  out.shape_region.assign(curves, -1);
  for (std::size_t i = 0; i < curves && i < shape_region.size(); ++i) out.shape_region[i] = shape_region[i];
  std::vector<int> sharing(regions.size(), 0);  // shapes that take each region's name
  for (std::size_t i = 0; i < curves && i < shape_region.size(); ++i)
    if (shape_region[i] >= 0) ++sharing[static_cast<std::size_t>(shape_region[i])];
  for (std::size_t i = 0; i < curves && i < shape_region.size(); ++i) {
    if (shape_region[i] < 0) continue;
    const auto r = static_cast<std::size_t>(shape_region[i]);
    // Several shapes of one name: "one of the white spots" (a plural name), "part of the left wing".
    const std::string name = region_said_name(regions[r], m);
    const NameKind kind = name_kind(regions[r]);
    const bool plural = kind == NameKind::plural;
    const bool shared = sharing[r] > 1 && kind != NameKind::proper;
    const std::string one_of = m.word("name_one_of", 1, {{"name", name}});
    out.shape_name[i] = shared ? (plural ? one_of : m.word("name_part_of", 1, {{"name", name}})) : name;
    out.part_name[i] = shared && plural ? one_of : name;
  }
  std::vector<std::size_t> order(regions.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return regions[a].area_px > regions[b].area_px; });
  const double m_per_px = px_to_m.scale_m_per_px;
  for (const std::size_t r : order) {
    const meaning::NamedRegion& nr = regions[r];
    const std::string name = region_said_name(nr, m);
    if (name.empty() || std::any_of(out.parts.begin(), out.parts.end(), [&](const auto& p) { return p.name == name; }))
      continue;
    const cv::Moments mo = cv::moments(nr.mask, true);
    const double u = nr.box_px.x + (mo.m00 > 0 ? mo.m10 / mo.m00 : nr.box_px.width / 2.0);
    const double v = nr.box_px.y + (mo.m00 > 0 ? mo.m01 / mo.m00 : nr.box_px.height / 2.0);
    out.parts.push_back({name,
                         {px_to_m.x_m(u), px_to_m.y_m(v)},
                         nr.area_px * m_per_px * m_per_px,
                         -1,
                         nr.source != meaning::RegionSource::staff});
  }
  if (polylines && polylines->size() == curves) longest_curve_of_each_part(regions, shape_region, *polylines, out, m);
  return out;
}

std::string shape_words(const ShownView& shown, std::size_t curve, const audio::MessageCatalog& m) {
  if (shown.tutorial && !shown.notes.title.empty()) return shown.notes.title;  // "a square"
  if (shown.names && curve < shown.names->shape_name.size() && !shown.names->shape_name[curve].empty())
    return shown.names->shape_name[curve];
  return describe_one_shape(shown.polylines, shown.descriptors, curve, shown.half_m, false, m);
}

namespace {

/// Whether region `r` is where the hand is: a region that names closed shapes (a box drawn round the horse)
/// holds the hand only inside one of them, so the air beside the horse is not "in the horse".
bool region_holds(const ShownView& shown, int r, Vec2 hand_m) {
  if (!shown.names) return true;
  bool names_closed = false;
  for (std::size_t i = 0; i < shown.names->shape_region.size() && i < shown.polylines.size(); ++i) {
    if (shown.names->shape_region[i] != r || !shown.polylines[i].closed) continue;
    names_closed = true;
    if (shape_holds(shown.polylines[i], hand_m)) return true;
  }
  return !names_closed;
}

}  // namespace

std::string shape_look(const ShownView& shown, std::size_t curve, const audio::MessageCatalog& m) {
  if (shown.tutorial && !shown.notes.title.empty()) return shown.notes.title;
  if (shown.names && curve < shown.names->shape_name.size() && !shown.names->shape_name[curve].empty())
    return shown.names->shape_name[curve];
  return describe_one_look(shown.polylines, shown.descriptors, curve, shown.half_m, m);
}

std::string where_answer(const ShownView& shown, const audio::MessageCatalog& m, Vec2 hand_m, int contact_curve) {
  const std::string place = place_words(hand_m, shown.half_m, m);
  if (const TextBlockM* b = text_block_at(shown.text_blocks, hand_m)) {
    const auto index = b - shown.text_blocks.data();
    return m.text(audio::MessageId::where_text,
                  {{"block", std::to_string(index + 1)},
                   {"blocks", std::to_string(shown.text_blocks.size())},
                   {"where", place},
                   {"text", first_words(name_unclear_words(b->text, m), kWhereTextWords)}});
  }
  const ShapeAtHand at = shape_at_hand(shown.polylines, shown.descriptors, hand_m, contact_curve);
  // The smallest named part under the hand: said on its own off every shape, beside the shape on one.
  std::string part;
  if (shown.regions) {
    const Vec2 px{shown.px_to_m.u_px(hand_m.x), shown.px_to_m.v_px(hand_m.y)};
    for (const int r : meaning::regions_at(*shown.regions, px.x, px.y))
      if (region_holds(shown, r, hand_m)) {
        part = region_said_name((*shown.regions)[static_cast<std::size_t>(r)], m);
        break;
      }
  }
  if (!at.on && !part.empty()) return m.text(audio::MessageId::where_region, {{"name", part}, {"where", place}});
  if (at.curve < 0) return m.text(audio::MessageId::where_none, {{"where", place}});
  const auto [number, count] =
      shape_number(shown.descriptors, shown.polylines.size(), static_cast<std::size_t>(at.curve));
  const auto curve = static_cast<std::size_t>(at.curve);
  const bool own_part = at.on && !part.empty() && shape_look(shown, curve, m).find(part) == std::string::npos;
  // On a shape: what it is, whole; with a part under the hand, or off it, its look only (said short).
  const std::string words = at.on && !own_part ? shape_words(shown, curve, m) : shape_look(shown, curve, m);
  const audio::MessageId id = own_part    ? audio::MessageId::where_on_part
                              : at.on     ? audio::MessageId::where_on
                              : at.inside ? audio::MessageId::where_inside
                                          : audio::MessageId::where_near;
  return m.text(id, {{"shape", std::to_string(number)},
                     {"name", part},
                     {"shapes", std::to_string(count)},
                     {"description", words},
                     {"where", place},
                     {"direction", direction_words(hand_m, at.nearest_m, m)}});
}

std::string describe_answer(const ShownView& shown, const audio::MessageCatalog& m, Vec2 hand_m, Vec2 proxy_m) {
  if (shown.page || !shown.text_blocks.empty()) {
    // A page (or a picture of one): the block of text under the hand is read; elsewhere, what the page holds.
    if (const TextBlockM* b = text_block_at(shown.text_blocks, proxy_m))
      return m.text(audio::MessageId::text_block, {{"text", name_unclear_words(b->text, m)}});
    const std::string page =
        describe_page(static_cast<int>(shown.text_blocks.size()), count_figures(shown.polylines), m);
    return shown.polylines.empty()
               ? page
               : page + " " +
                     describe_scene(shown.polylines, shown.descriptors, shown.half_m, 3, hand_m, shown.names, m);
  }
  if (shown.tutorial && !shown.notes.title.empty())  // a practice shape: "A square, in the middle."
    return sentence_case(
        m.word("shape_at", 1, {{"shape", shown.notes.title}, {"place", place_words({0.0, 0.0}, shown.half_m, m)}}));
  return notes_words(shown.notes) +
         describe_scene(shown.polylines, shown.descriptors, shown.half_m, 3, hand_m, shown.names, m);
}

}  // namespace hk::app
