// The directives of a pbrt-v4 file (the format page): the reading loop, Include/Import, the
// attribute and object stacks, the transforms, and the dispatch of every typed directive to the
// part of the reader that builds it.
#include "scene/pbrt/reader.h"
#include "scene/pbrt/transforms.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <set>
#include <system_error>

namespace canopy::pbrt {

namespace {

constexpr int kMaxIncludeDepth = 64;

} // namespace

void Reader::run_file(const std::filesystem::path& file, const std::string& display,
                      const Loc* from) {
  std::error_code ec;
  std::string canon = std::filesystem::weakly_canonical(file, ec).string();
  if (ec) canon = file.lexically_normal().string();
  for (size_t k = 0; k < include_stack_.size(); ++k)
    if (include_stack_[k].first == canon) {
      std::string chain;
      for (size_t m = k; m < include_stack_.size(); ++m)
        chain += include_stack_[m].second + " -> ";
      fail(*from, fmt::format("Include cycle: {}{}", chain, display));
    }
  if (include_stack_.size() >= size_t(kMaxIncludeDepth))
    fail(*from, fmt::format("Includes nested deeper than {}", kMaxIncludeDepth));
  std::string prefix =
      from ? fmt::format("{}:{}: Include \"{}\": ", *from->file, from->line, display)
           : display + ": ";
  std::string text = read_input_file(file, kMaxSceneFileBytes, prefix);
  include_stack_.push_back({canon, display});
  run_text(text, display, file.parent_path());
  include_stack_.pop_back();
}

void Reader::run_text(const std::string& text, const std::string& display,
                      const std::filesystem::path& dir) {
  names_.push_back(display);
  Lexer lx(text, &names_.back());
  while (lx.peek()) {
    const Token d = lx.next();
    if (d.kind != Tok::Ident || is_bool_ident(d))
      fail(d.loc, fmt::format("expected a directive, got {}", describe(d)));
    last_loc_ = d.loc;
    directive(d, lx, dir);
  }
}

std::vector<double> Reader::numbers(const Token& d, Lexer& lx, size_t want, bool brackets_ok) {
  std::vector<double> v;
  const bool br = brackets_ok && lx.peek() && lx.peek()->kind == Tok::LBracket;
  if (br) lx.next();
  while (v.size() <= want) { // one more than wanted is enough to report the count
    if (br && lx.peek() && lx.peek()->kind == Tok::RBracket) {
      lx.next();
      break;
    }
    if (lx.at_directive()) {
      if (br) fail(d.loc, fmt::format("{}: '[' without ']'", d.text));
      break;
    }
    Token t = lx.next();
    if (t.kind != Tok::Number)
      fail(t.loc, fmt::format("{}: expected a number, got {}", d.text, describe(t)));
    v.push_back(t.num);
  }
  if (v.size() != want)
    fail(d.loc, fmt::format("{}: wrong count of values ({}{}; want {} numbers)", d.text,
                            v.size() > want ? "more than " : "", std::min(v.size(), want), want));
  if (!lx.at_directive())
    fail(lx.peek()->loc, fmt::format("{}: unexpected {}", d.text, describe(*lx.peek())));
  return v;
}

std::string Reader::one_string(const Token& d, Lexer& lx) {
  const Token* t = lx.peek();
  if (!t || t->kind != Tok::String)
    fail(t && !lx.at_directive() ? t->loc : d.loc,
         fmt::format("{}: expected a quoted name{}", d.text,
                     t && !lx.at_directive() ? ", got " + describe(*t) : ""));
  return lx.next().text;
}

void Reader::directive(const Token& d, Lexer& lx, const std::filesystem::path& dir) {
  const std::string& k = d.text;
  dir_ = dir;
  auto no_args = [&] {
    if (!lx.at_directive())
      fail(lx.peek()->loc, fmt::format("{}: unexpected {}", k, describe(*lx.peek())));
  };
  auto skip = [&] { // the arguments of a directive that is not read
    while (!lx.at_directive())
      lx.next();
  };
  auto need_world = [&](bool inside) {
    if (world_block_ != inside)
      fail(d.loc, fmt::format("{} is not allowed {} WorldBegin", k, inside ? "before" : "after"));
  };
  auto post = [&](const Transform& x) { gs_.ctm = x.then(gs_.ctm); }; // CTM = CTM * x

  // ---- structure (the format page, "Scene-wide rendering options" / "Attributes")
  if (k == "Include" || k == "Import") {
    // Import may only add named things in pbrt-v4 (it exists so files can be parsed in
    // parallel); read sequentially, it is the same as Include.
    std::string f = one_string(d, lx);
    no_args();
    std::filesystem::path p(f);
    if (p.is_relative()) p = dir / p;
    run_file(p, p.lexically_normal().string(), &d.loc);
  } else if (k == "AttributeBegin" || k == "TransformBegin") {
    // TransformBegin/End: deprecated in pbrt-v4 but accepted there; they save the CTM only.
    no_args();
    stack_.push_back({gs_, d.loc, k});
  } else if (k == "AttributeEnd" || k == "TransformEnd") {
    no_args();
    const char* open = k == "AttributeEnd" ? "AttributeBegin" : "TransformBegin";
    if (stack_.empty() || stack_.back().kind != open)
      fail(d.loc, stack_.empty() ? fmt::format("{} without {}", k, open)
                                 : fmt::format("{} closes the {} of line {}", k, stack_.back().kind,
                                               stack_.back().loc.line));
    if (k == "AttributeEnd")
      gs_ = stack_.back().gs;
    else
      gs_.ctm = stack_.back().gs.ctm;
    stack_.pop_back();
  } else if (k == "WorldBegin") {
    no_args();
    need_world(false);
    finish_camera(d.loc);
    world_block_ = true;
    gs_.ctm = Transform{};
    coord_systems_["world"] = Transform{};
  } else if (k == "ReverseOrientation") {
    no_args();
    gs_.reverse = !gs_.reverse;
  } else if (k == "Option") {
    warn(d.loc, "Option: rendering options are not read, ignored");
    skip();
  } else if (k == "ObjectBegin") {
    // Object instances are flattened: each ObjectInstance copies the object's triangles with the
    // instance transform into the one triangle soup (Canopy's BVH has no instance level). Memory
    // grows with instances x triangles, capped by kMaxTriangles.
    need_world(true);
    std::string name = one_string(d, lx);
    no_args();
    if (object_) fail(d.loc, "ObjectBegin inside another ObjectBegin");
    if (objects_.count(name))
      fail(d.loc, fmt::format("object \"{}\" is defined twice", printable(name)));
    stack_.push_back({gs_, d.loc, "ObjectBegin"}); // pbrt-v4: ObjectBegin implies AttributeBegin
    object_ = &objects_[name];
  } else if (k == "ObjectEnd") {
    no_args();
    if (!object_ || stack_.empty() || stack_.back().kind != "ObjectBegin")
      fail(d.loc, stack_.empty() || !object_
                      ? std::string("ObjectEnd without ObjectBegin")
                      : fmt::format("ObjectEnd closes the {} of line {}", stack_.back().kind,
                                    stack_.back().loc.line));
    gs_ = stack_.back().gs;
    stack_.pop_back();
    object_ = nullptr;
  } else if (k == "ObjectInstance") {
    need_world(true);
    std::string name = one_string(d, lx);
    no_args();
    if (object_) fail(d.loc, "ObjectInstance inside ObjectBegin");
    auto it = objects_.find(name);
    if (it == objects_.end()) fail(d.loc, fmt::format("unknown object \"{}\"", printable(name)));
    for (ObjectPart& part : it->second)
      add_mesh(d.loc, part.mesh, part.xf.then(gs_.ctm));
  }
  // ---- transforms (the format page, "Transformations"); pbrt post-multiplies the CTM
  else if (k == "Identity") {
    no_args();
    gs_.ctm = Transform{};
  } else if (k == "Translate") {
    auto v = numbers(d, lx, 3, false);
    post(Transform::translate({v[0], v[1], v[2]}));
  } else if (k == "Scale") {
    auto v = numbers(d, lx, 3, false);
    post(Transform::scale({v[0], v[1], v[2]}));
  } else if (k == "Rotate") {
    auto v = numbers(d, lx, 4, false);
    double3 ax{v[1], v[2], v[3]};
    double l = len3(ax);
    if (!(l > 0.0) || !std::isfinite(l)) fail(d.loc, "Rotate: the axis must be non-zero");
    post(Transform::rotate(ax * (1.0 / l), v[0]));
  } else if (k == "LookAt") {
    auto v = numbers(d, lx, 9, false);
    double3 eye{v[0], v[1], v[2]}, at{v[3], v[4], v[5]}, up{v[6], v[7], v[8]};
    double3 dirv = at - eye;
    double dl = len3(dirv), ul = len3(up);
    if (!(dl > 0.0) || !std::isfinite(dl)) fail(d.loc, "LookAt: eye and target coincide");
    if (!(ul > 0.0) || !std::isfinite(ul)) fail(d.loc, "LookAt: the up vector is zero");
    dirv = dirv * (1.0 / dl);
    // pbrt-v4 LookAt: right = normalize(cross(normalize(up), dir)), newUp = cross(dir, right);
    // worldFromCamera has columns right, newUp, dir and the eye; the CTM gets its inverse.
    double3 right = cross3(up * (1.0 / ul), dirv);
    double rl = len3(right);
    if (!(rl > 1e-9)) fail(d.loc, "LookAt: the up vector is parallel to the view direction");
    right = right * (1.0 / rl);
    double3 nup = cross3(dirv, right);
    Transform cam_from_world; // the transpose of the rotation, then minus the rotated eye
    double3 rows[3] = {right, nup, dirv};
    for (int i = 0; i < 3; ++i) {
      cam_from_world.m[i][0] = rows[i].x;
      cam_from_world.m[i][1] = rows[i].y;
      cam_from_world.m[i][2] = rows[i].z;
    }
    cam_from_world.t = {-dot3(right, eye), -dot3(nup, eye), -dot3(dirv, eye)};
    post(cam_from_world);
  } else if (k == "Transform" || k == "ConcatTransform") {
    Transform x = from_pbrt_matrix(d.loc, numbers(d, lx, 16, true));
    if (k == "Transform")
      gs_.ctm = x;
    else
      post(x);
  } else if (k == "CoordinateSystem") {
    std::string name = one_string(d, lx);
    no_args();
    coord_systems_[name] = gs_.ctm;
  } else if (k == "CoordSysTransform") {
    std::string name = one_string(d, lx);
    no_args();
    auto it = coord_systems_.find(name);
    if (it == coord_systems_.end())
      warn(d.loc, fmt::format("CoordSysTransform: unknown coordinate system \"{}\" ignored",
                              printable(name)));
    else
      gs_.ctm = it->second;
  }
  // ---- everything with a type name and a parameter list
  else {
    static const std::set<std::string> typed = {
        "Camera",          "Film",        "Sampler",
        "Integrator",      "PixelFilter", "Accelerator",
        "ColorSpace",      "Shape",       "LightSource",
        "AreaLightSource", "Material",    "MakeNamedMaterial",
        "NamedMaterial",   "Texture",     "MakeNamedMedium",
        "MediumInterface", "Attribute",   "ActiveTransform",
        "TransformTimes"};
    if (!typed.count(k)) {
      warn(d.loc, fmt::format("unknown directive '{}' ignored", printable(k)));
      skip();
      return;
    }
    if (k == "Texture") {
      need_world(true);
      std::string name = one_string(d, lx);
      std::string type = one_string(d, lx);
      std::string cls = one_string(d, lx);
      Params p(*this, parse_params(lx), fmt::format("Texture \"{}\"", printable(name, 40)));
      texture(d, p, name, type, cls, dir);
      return;
    }
    if (k == "MediumInterface") { // "inside" ["outside"]: one name is both
      std::vector<std::string> names{one_string(d, lx)};
      if (!lx.at_directive()) names.push_back(one_string(d, lx));
      no_args();
      medium_interface(d, names);
      return;
    }
    if (k == "MakeNamedMedium") {
      std::string name = one_string(d, lx);
      Params p(*this, parse_params(lx), fmt::format("MakeNamedMedium \"{}\"", printable(name, 40)));
      make_named_medium(d, p, name);
      return;
    }
    if (k == "Attribute" || k == "ActiveTransform" || k == "TransformTimes" || k == "PixelFilter" ||
        k == "Accelerator" || k == "ColorSpace") {
      warn(d.loc, fmt::format("{} is not read in this slice, ignored", k));
      skip();
      return;
    }
    std::string type = one_string(d, lx);
    if (k == "NamedMaterial") {
      no_args();
      auto it = named_materials_.find(type);
      if (it == named_materials_.end())
        fail(d.loc, fmt::format("NamedMaterial: unknown material \"{}\"", printable(type)));
      gs_.material = it->second;
      return;
    }
    Params p(*this, parse_params(lx), fmt::format("{} \"{}\"", k, printable(type, 40)));
    if (k == "Camera") {
      need_world(false);
      camera(d, p, type);
    } else if (k == "Film") {
      need_world(false);
      if (type != "rgb")
        warn(d.loc, fmt::format("Film \"{}\": read as \"rgb\" (its other outputs ignored)",
                                printable(type)));
      auto res = [&](const char* name, int& out) {
        if (Param* q = p.one(name, {"integer"})) {
          double v = q->nums[0];
          if (!(v >= 1 && v <= kMaxFilmSide))
            fail(q->loc, fmt::format("{}: \"integer {}\": must be in [1, {}]", p.what(), name,
                                     kMaxFilmSide));
          out = int(v);
        }
      };
      res("xresolution", scene_.film.width);
      res("yresolution", scene_.film.height);
      // pbrt-v4 (FilmBaseParameters) writes `filename` as given, relative to the working
      // directory; here it is the default of --out. Canopy writes EXR and PNG: another extension
      // is replaced by .exr, with a warning.
      if (auto f = p.get_string("filename")) {
        std::filesystem::path out(*f);
        std::string ext = out.extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(),
                       [](unsigned char c) { return char(std::tolower(c)); });
        if (f->empty() || out.filename().empty())
          fail(p.find("filename")->loc, fmt::format("{}: \"string filename\": empty", p.what()));
        if (ext != ".exr" && ext != ".png") {
          warn(p.find("filename")->loc,
               fmt::format("{}: \"string filename\" \"{}\": Canopy writes EXR and PNG, written "
                           "as .exr",
                           p.what(), printable(*f)));
          out.replace_extension(".exr");
        }
        scene_.film.output = out.string();
      }
      // The image scale: pbrt-v4's RGBFilm multiplies by its sensor's imaging ratio, ISO / 100
      // for the default sensor (and the shutter time, 1 by default); pbrt-v3's "scale" multiplies
      // too. Both are read, as one factor.
      double scale = p.get_float("scale", 1.0) * p.get_float("iso", 100.0) / 100.0;
      if (!(scale > 0.0 && scale <= 1e30))
        fail(d.loc, fmt::format("{}: the image scale (scale x iso / 100 = {}) must be in "
                                "(0, 1e30]",
                                p.what(), scale));
      scene_.film.image_scale = float(scale);
      p.finish();
    } else if (k == "Sampler") {
      need_world(false);
      count_param(p, "pixelsamples", kMaxSpp, &scene_.integrator.spp);
      p.finish();
    } else if (k == "Integrator") {
      need_world(false);
      // "path" and "volpath" are what Canopy renders (paths with light sampling and MIS, pbrt's
      // maxdepth); any other integrator is replaced by it.
      if (type != "path" && type != "volpath")
        warn(d.loc, fmt::format("Integrator \"{}\": rendered with Canopy's path tracer, the "
                                "integrator ignored",
                                printable(type)));
      integrator_ = type;
      count_param(p, "maxdepth", kMaxDepth, &scene_.integrator.max_depth);
      p.finish();
    } else if (k == "Shape") {
      need_world(true);
      shape(d, p, type, dir);
    } else if (k == "LightSource") {
      need_world(true);
      light_source(d, p, type, dir);
    } else if (k == "AreaLightSource") {
      need_world(true);
      area_light(d, p, type);
    } else if (k == "Material") {
      need_world(true);
      gs_.material = material(d.loc, p, type, "");
    } else { // MakeNamedMaterial "name" "string type" "..." params
      need_world(true);
      auto t = p.get_string("type");
      if (!t) fail(d.loc, "MakeNamedMaterial: needs a \"string type\" parameter");
      if (named_materials_.count(type))
        fail(d.loc, fmt::format("MakeNamedMaterial: \"{}\" is defined twice", printable(type)));
      named_materials_[type] = material(d.loc, p, *t, type);
    }
  }
}

void Reader::count_param(Params& p, const char* name, int hi, int* out) {
  if (Param* q = p.one(name, {"integer"})) {
    if (!(q->nums[0] >= 1 && q->nums[0] <= hi))
      fail(q->loc, fmt::format("{}: \"integer {}\": must be in [1, {}]", p.what(), name, hi));
    *out = int(q->nums[0]);
  }
}

void Reader::finish() {
  const Loc end = last_loc_.file ? last_loc_ : Loc{&names_.front(), 1};
  if (!world_block_) finish_camera(end); // a file without WorldBegin: camera and options only
  finish_media();
  if (!stack_.empty())
    warn(stack_.back().loc,
         fmt::format("{} without its end at the end of the file, ignored", stack_.back().kind));
  if (dropped_warnings_ > 0)
    scene_.warnings.push_back(fmt::format("{}: {} more warnings", b_.file, dropped_warnings_));
}

} // namespace canopy::pbrt
