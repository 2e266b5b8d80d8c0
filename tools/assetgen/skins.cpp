// The 27 skins of the pack: one Look per name (colours and accessories that
// make the name recognisable) and its frame count (2, or 3 for a few).
#include <map>

#include "tools/assetgen/sprite_draw.h"

namespace kage::assetgen {
namespace {

struct SkinDef {
  Look look;
  int frames = 2;
};

constexpr Px rgb(int r, int g, int b) { return Px{uint8_t(r), uint8_t(g), uint8_t(b), 255}; }

const Px kPale = rgb(246, 214, 186), kTan = rgb(214, 160, 118), kBrownSkin = rgb(150, 100, 66);
const Px kSteel = rgb(150, 156, 168), kBone = rgb(236, 232, 214);

std::map<std::string, SkinDef> build() {
  std::map<std::string, SkinDef> m;
  Look k;

  k = Look{};  // boy: short brown hair, blue tee, shorts, red sneakers; a bit shorter
  k.top_color = rgb(50, 110, 220);
  k.lower = Lower::kShorts;
  k.lower_color = rgb(70, 70, 90);
  k.shoes = rgb(210, 40, 40);
  k.top_offset = 2;
  m["boy"] = {k};

  k = Look{};  // chibi: big head, pink hair, bow
  k.body = Body::kChibi;
  k.skin = kPale;
  k.hair = rgb(240, 120, 180);
  k.hair_style = Hair::kPigtails;
  k.hat_trim = rgb(255, 230, 60);
  k.eyes = rgb(60, 40, 120);
  k.top_color = rgb(255, 190, 220);
  k.lower = Lower::kSkirt;
  k.lower_color = rgb(150, 90, 210);
  k.shoes = rgb(90, 50, 120);
  k.crop = true;
  m["chibi"] = {k};

  k = Look{};  // clown: white face, red nose, orange afro, dotted split suit, balloon
  k.skin = rgb(250, 250, 250);
  k.hair = rgb(255, 110, 20);
  k.hair_style = Hair::kAfro;
  k.face = Face::kClown;
  k.top = Top::kDots;
  k.top_color = rgb(250, 220, 30);
  k.top_color2 = rgb(150, 40, 200);
  k.lower_color = rgb(40, 180, 80);
  k.shoes = rgb(230, 30, 40);
  k.item = Item::kBalloon;
  k.item_color = rgb(240, 40, 60);
  k.glow = Px{255, 120, 160, 128};
  m["clown"] = {k};

  k = Look{};  // cowboy: brown wide hat, red bandana, tan shirt, jeans, boots
  k.skin = kTan;
  k.hat = Hat::kCowboy;
  k.hat_color = rgb(140, 90, 45);
  k.hat_trim = rgb(90, 55, 25);
  k.top = Top::kTie;
  k.top_color = rgb(200, 160, 100);
  k.top_color2 = rgb(200, 30, 30);
  k.lower_color = rgb(60, 90, 160);
  k.shoes = rgb(100, 60, 30);
  m["cowboy"] = {k};

  k = Look{};  // cowboy_2: black hat, vest with sheriff star
  k.skin = kBrownSkin;
  k.hair = rgb(30, 20, 15);
  k.hat = Hat::kCowboy;
  k.hat_color = rgb(35, 30, 30);
  k.hat_trim = rgb(180, 180, 190);
  k.top = Top::kStar;
  k.top_color = rgb(80, 50, 35);
  k.top_color2 = rgb(235, 230, 215);
  k.lower_color = rgb(110, 110, 115);
  k.shoes = rgb(60, 35, 20);
  k.crop = true;
  m["cowboy_2"] = {k};

  k = Look{};  // dark_knight: black armour, red visor, purple cape, sword
  k.skin = rgb(60, 58, 70);
  k.hat = Hat::kHelmet;
  k.hat_color = rgb(45, 42, 55);
  k.hat_trim = rgb(230, 30, 40);
  k.cape = true;
  k.cape_color = rgb(90, 20, 110);
  k.top_color = rgb(50, 48, 62);
  k.lower_color = rgb(40, 38, 50);
  k.shoes = rgb(25, 22, 30);
  k.item = Item::kSword;
  k.item_color = rgb(120, 110, 140);
  k.outline = rgb(10, 6, 14);
  m["dark_knight"] = {k, 3};

  k = m["dark_knight"].look;  // dark_knight_2: horned steel-blue armour, axe, no cape
  k.hat = Hat::kHorned;
  k.hat_color = rgb(60, 70, 95);
  k.hat_trim = rgb(255, 150, 30);
  k.cape = false;
  k.top_color = rgb(65, 75, 100);
  k.lower_color = rgb(50, 58, 80);
  k.item = Item::kAxe;
  k.item_color = rgb(170, 175, 190);
  m["dark_knight_2"] = {k};

  k = Look{};  // dark_skeleton: dark bones, glowing purple eyes
  k.body = Body::kSkeleton;
  k.hair_style = Hair::kNone;
  k.skin = rgb(92, 86, 104);
  k.eyes = rgb(200, 80, 255);
  k.glow_eyes = true;
  k.glow = Px{170, 60, 255, 128};
  k.outline = rgb(16, 10, 22);
  m["dark_skeleton"] = {k, 3};

  k = Look{};  // dog: brown, floppy ears, red collar
  k.body = Body::kDog;
  k.skin = rgb(170, 110, 60);
  k.hat_trim = rgb(220, 30, 40);
  m["dog"] = {k};

  k = Look{};  // elder_skeleton: white bones, grey beard, hood, glowing staff
  k.body = Body::kSkeleton;
  k.hair_style = Hair::kNone;
  k.skin = kBone;
  k.hair = rgb(175, 175, 180);
  k.face = Face::kBeard;
  k.hat = Hat::kHood;
  k.hat_color = rgb(95, 70, 50);
  k.item = Item::kStaff;
  k.item_color = rgb(120, 230, 170);
  k.glow = Px{120, 255, 180, 128};
  m["elder_skeleton"] = {k, 3};

  k = Look{};  // elf: blond, green cap and tunic, bow-less but pointy-eared
  k.skin = kPale;
  k.hair = rgb(240, 210, 100);
  k.hair_style = Hair::kLong;
  k.hat = Hat::kCap;
  k.hat_color = rgb(40, 150, 60);
  k.hat_trim = kPale;
  k.top_color = rgb(50, 160, 70);
  k.lower_color = rgb(120, 85, 50);
  k.shoes = rgb(90, 60, 35);
  k.crop = true;
  m["elf"] = {k};

  k = Look{};  // enchanter: purple robe and hat, glowing orb staff
  k.skin = kPale;
  k.hair = rgb(200, 200, 210);
  k.hat = Hat::kWizard;
  k.hat_color = rgb(110, 40, 160);
  k.hat_trim = rgb(250, 220, 60);
  k.top = Top::kRobe;
  k.top_color = rgb(120, 50, 170);
  k.top_color2 = rgb(250, 220, 60);
  k.lower = Lower::kLong;
  k.lower_color = rgb(100, 40, 150);
  k.item = Item::kStaff;
  k.item_color = rgb(120, 200, 255);
  k.crop = true;
  m["enchanter"] = {k};

  k = Look{};  // farmer: straw hat, red shirt, blue overalls, pitchfork
  k.skin = kTan;
  k.hat = Hat::kStraw;
  k.hat_color = rgb(235, 200, 90);
  k.hat_trim = rgb(200, 50, 40);
  k.top = Top::kOveralls;
  k.top_color = rgb(200, 50, 40);
  k.lower_color = rgb(60, 90, 170);
  k.item = Item::kPitchfork;
  k.item_color = rgb(160, 160, 170);
  m["farmer"] = {k};

  k = Look{};  // girl: long brown hair, pink dress
  k.skin = kPale;
  k.hair = rgb(120, 70, 35);
  k.hair_style = Hair::kLong;
  k.top_color = rgb(240, 110, 170);
  k.lower = Lower::kSkirt;
  k.lower_color = rgb(240, 110, 170);
  k.shoes = rgb(200, 40, 90);
  m["girl"] = {k};

  k = Look{};  // girl_2: blonde pigtails, yellow top, blue skirt
  k.skin = kPale;
  k.hair = rgb(250, 220, 90);
  k.hair_style = Hair::kPigtails;
  k.hat_trim = rgb(60, 160, 230);
  k.top_color = rgb(250, 210, 40);
  k.lower = Lower::kSkirt;
  k.lower_color = rgb(50, 110, 210);
  k.shoes = rgb(240, 240, 240);
  m["girl_2"] = {k, 3};

  k = Look{};  // girl_3: black bob, red dress, narrow
  k.skin = kBrownSkin;
  k.hair = rgb(20, 18, 25);
  k.hair_style = Hair::kBob;
  k.top_color = rgb(210, 30, 50);
  k.lower = Lower::kLong;
  k.lower_color = rgb(190, 25, 45);
  k.shoes = rgb(40, 30, 30);
  k.crop = true;
  m["girl_3"] = {k};

  k = Look{};  // knight: grey plate armour, red plume, shield
  k.skin = kSteel;
  k.hat = Hat::kHelmet;
  k.hat_color = rgb(170, 176, 188);
  k.hat_trim = rgb(40, 40, 50);
  k.cape_color = rgb(220, 40, 40);
  k.top_color = rgb(165, 170, 182);
  k.lower_color = rgb(140, 145, 158);
  k.shoes = rgb(100, 104, 115);
  k.item = Item::kShield;
  k.item_color = rgb(40, 80, 200);
  k.hat_trim = rgb(40, 40, 50);
  k.crop = true;
  m["knight"] = {k};

  k = Look{};  // man: short black hair, white shirt, blue tie, grey trousers
  k.hair = rgb(30, 25, 20);
  k.top = Top::kTie;
  k.top_color = rgb(240, 240, 245);
  k.top_color2 = rgb(240, 240, 245);
  k.hat_trim = rgb(40, 70, 170);
  k.lower_color = rgb(90, 90, 100);
  k.shoes = rgb(30, 25, 25);
  k.crop = true;
  m["man"] = {k};

  k = Look{};  // robot: boxy metal, cyan visor, antenna with glowing tip, chest panel
  k.skin = rgb(175, 185, 195);
  k.hair_style = Hair::kNone;
  k.hat = Hat::kAntenna;
  k.hat_color = rgb(120, 125, 135);
  k.hat_trim = rgb(255, 60, 60);
  k.glow = Px{255, 90, 90, 128};
  k.face = Face::kVisor;
  k.eyes = rgb(60, 230, 255);
  k.top = Top::kPanel;
  k.top_color = rgb(150, 160, 175);
  k.lower_color = rgb(110, 118, 130);
  k.shoes = rgb(70, 75, 85);
  m["robot"] = {k};

  k = Look{};  // scientist: messy grey hair, glasses, lab coat
  k.skin = kPale;
  k.hair = rgb(200, 200, 205);
  k.hair_style = Hair::kMessy;
  k.face = Face::kGlasses;
  k.top = Top::kLabCoat;
  k.top_color = rgb(248, 248, 250);
  k.top_color2 = rgb(90, 150, 90);
  k.lower_color = rgb(60, 60, 70);
  k.shoes = rgb(40, 30, 25);
  k.crop = true;
  m["scientist"] = {k};

  k = Look{};  // skeleton: white bones on transparent
  k.body = Body::kSkeleton;
  k.hair_style = Hair::kNone;
  k.skin = kBone;
  k.outline = rgb(60, 56, 66);
  m["skeleton"] = {k};

  k = Look{};  // spy: fedora, sunglasses, trench coat
  k.hair = rgb(40, 30, 20);
  k.hat = Hat::kFedora;
  k.hat_color = rgb(40, 40, 45);
  k.hat_trim = rgb(120, 30, 30);
  k.face = Face::kShades;
  k.top = Top::kLabCoat;
  k.top_color = rgb(190, 160, 110);
  k.top_color2 = rgb(30, 30, 35);
  k.lower_color = rgb(35, 35, 40);
  k.shoes = rgb(20, 20, 20);
  k.crop = true;
  m["spy"] = {k};

  k = Look{};  // thief: dark hood, eye mask, loot bag
  k.hat = Hat::kHood;
  k.hat_color = rgb(50, 50, 60);
  k.face = Face::kMask;
  k.top_color = rgb(55, 55, 68);
  k.lower_color = rgb(35, 35, 45);
  k.shoes = rgb(25, 25, 30);
  k.item = Item::kBag;
  k.item_color = rgb(170, 130, 80);
  k.crop = true;
  m["thief"] = {k};

  k = Look{};  // warrior: red headband, bare arms, fur, sword
  k.skin = kTan;
  k.hair = rgb(60, 35, 20);
  k.hair_style = Hair::kSpiky;
  k.hat = Hat::kHeadband;
  k.hat_color = rgb(210, 30, 30);
  k.top = Top::kVest;
  k.top_color = rgb(130, 85, 45);
  k.top_color2 = kTan;
  k.lower_color = rgb(100, 70, 40);
  k.shoes = rgb(70, 45, 25);
  k.item = Item::kSword;
  k.item_color = rgb(210, 215, 225);
  m["warrior"] = {k};

  k = Look{};  // woman: long red hair, green dress
  k.skin = kPale;
  k.hair = rgb(200, 60, 30);
  k.hair_style = Hair::kLong;
  k.top_color = rgb(40, 150, 90);
  k.lower = Lower::kLong;
  k.lower_color = rgb(35, 135, 80);
  k.shoes = rgb(60, 40, 30);
  k.crop = true;
  m["woman"] = {k};

  k = Look{};  // woman_2: blonde bun, purple blouse, black skirt
  k.skin = kTan;
  k.hair = rgb(245, 215, 120);
  k.hair_style = Hair::kBun;
  k.top_color = rgb(150, 70, 190);
  k.lower = Lower::kSkirt;
  k.lower_color = rgb(35, 30, 40);
  k.shoes = rgb(150, 20, 40);
  k.crop = true;
  m["woman_2"] = {k, 3};

  k = Look{};  // woman_wizard: blue pointed hat, starry robe, glowing staff
  k.skin = kPale;
  k.hair = rgb(230, 230, 240);
  k.hair_style = Hair::kLong;
  k.hat = Hat::kWizard;
  k.hat_color = rgb(40, 70, 190);
  k.hat_trim = rgb(255, 240, 120);
  k.top = Top::kStar;
  k.top_color = rgb(50, 80, 200);
  k.top_color2 = rgb(70, 110, 230);
  k.lower = Lower::kLong;
  k.lower_color = rgb(45, 75, 195);
  k.item = Item::kStaff;
  k.item_color = rgb(255, 240, 140);
  k.glow = Px{255, 240, 140, 128};
  m["woman_wizard"] = {k};
  return m;
}

const std::map<std::string, SkinDef>& defs() {
  static const std::map<std::string, SkinDef> m = build();
  return m;
}

}  // namespace

const std::vector<std::string>& skin_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& [name, def] : defs()) v.push_back(name);
    return v;
  }();
  return names;
}

std::string skin_file_stem(const std::string& name) { return name; }

std::vector<Image> make_skin(const std::string& name) {
  const SkinDef& def = defs().at(name);
  static const int kTwo[] = {0, 2};
  static const int kThree[] = {0, 1, 2};
  std::vector<Image> frames;
  for (int i = 0; i < def.frames; ++i) frames.push_back(draw_figure(def.look, def.frames == 3 ? kThree[i] : kTwo[i]));
  return frames;
}

}  // namespace kage::assetgen
