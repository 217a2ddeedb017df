// Volumes deformed and cut (Correa, Silver, Chen 2006): the data and its maps
// (ibr/volume_object.h), drawn by render::VolumePass (DVR translucent, after
// the opaque objects; iso opaque).
#include "ibr/kinds/volume_kind.h"

#include <fmt/format.h>

#include "core/error.h"
#include "ibr/kinds/kinds.h"
#include "ibr/views.h"
#include "render/passes/volume_pass.h"

namespace ibr {
namespace {

std::string PassName(const VolumeObjectOptions& options) {
  return options.pass.mode == render::VolumeMode::kDvr ? "volume:dvr" : "volume:iso";
}

class VolumeObjectPass final : public ObjectPass {
 public:
  VolumeObjectPass(render::ProgramCache& programs, const VolumeState& s)
      : name_(PassName(s.options)),
        pass_(programs, s.data->volume, s.data->transfer, s.data->maps, s.data->world_from_volume,
              s.options.pass) {}
  render::Pass& pass() override { return pass_; }
  std::string name() const override { return name_; }
  render::VolumePass& volume() { return pass_; }
  const render::VolumePass& volume() const { return pass_; }
  void set_name(std::string name) { name_ = std::move(name); }

 private:
  std::string name_;
  render::VolumePass pass_;
};

class VolumeKindImpl final : public ObjectKind {
 public:
  scene::ObjectType type() const override { return scene::ObjectType::kVolume; }
  std::any Options(const scene::Settings& settings) const override {
    return VolumeObjectOptionsFrom(settings);
  }
  LoadedObject Load(render::ProgramCache&, const scene::Object& o) const override {
    kinds::UniformScale(o.world_from_object, o.where);
    return LoadedVolumeObject(o.name, LoadVolumeObject(o));
  }
  std::unique_ptr<ObjectPass> MakePass(render::ProgramCache& programs,
                                       const LoadedObject& object) const override {
    return std::make_unique<VolumeObjectPass>(programs, VolumeOf(object));
  }
};

}  // namespace

const ObjectKind& VolumeKind() {
  static const VolumeKindImpl kind;
  return kind;
}

LoadedObject LoadedVolumeObject(std::string name, LoadedVolume volume) {
  LoadedObject l;
  l.name = std::move(name);
  l.type = scene::ObjectType::kVolume;
  VolumeState s{std::make_shared<const VolumeObjectData>(std::move(volume.data)), volume.options};
  l.bounds = BoxBounds(WorldFromProxy(*s.data));
  l.data = std::move(s);
  return l;
}

const render::VolumePass& VolumePassOf(const ObjectPass& pass) {
  const auto* p = dynamic_cast<const VolumeObjectPass*>(&pass);
  IBR_CHECK(p != nullptr);
  return p->volume();
}

VolumeState& VolumeOf(LoadedObject& object) { return KindState<VolumeState>(object); }
const VolumeState& VolumeOf(const LoadedObject& object) { return KindState<VolumeState>(object); }

VolumeObjectChange UpdateVolumeKind(LoadedObject& l, ObjectPass& object_pass,
                                    const VolumeObjectOptions& options, bool preview) {
  VolumeState& s = VolumeOf(l);
  auto* p = dynamic_cast<VolumeObjectPass*>(&object_pass);
  IBR_CHECK(p != nullptr);
  const std::string where = fmt::format("object '{}'", l.name);
  // The maps changed aside (the volume itself is copied only when they do).
  VolumeObjectData maps_only;
  maps_only.maps = s.data->maps;
  maps_only.preview_maps = s.data->preview_maps;
  const VolumeObjectChange change =
      UpdateVolumeObject(maps_only, s.options, options, where, preview);
  if (!change.Any()) return change;
  try {
    // The volume's texture stays: only the maps are uploaded anew (what a
    // drag of a deformation's parameter changes), then the options; a
    // transfer-function edit rewrites only the 1D table (none: back to the
    // function loaded).
    if (change.maps) p->volume().SetMaps(maps_only.maps);
    p->volume().SetOptions(options.pass);
    if (change.transfer) {
      p->volume().SetTransferFunction(
          options.transfer
              ? core::NormalizedTransfer(*options.transfer, s.data->volume.NormalizationRange())
              : s.data->transfer);
    }
  } catch (const core::InputError& e) {
    throw core::InputError(fmt::format("{}: {}", where, e.what()));
  }
  if (change.maps) {
    auto data = std::make_shared<VolumeObjectData>(*s.data);
    data->maps = std::move(maps_only.maps);
    data->preview_maps = maps_only.preview_maps;
    s.data = std::move(data);
    l.bounds = BoxBounds(WorldFromProxy(*s.data));
  }
  s.options = options;
  p->set_name(PassName(options));
  return change;
}

}  // namespace ibr
