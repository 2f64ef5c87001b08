// Weft's main pass: sky, ground grid, lit two-sided surfaces, lines and point markers.
// All colours are linear; the target is sRGB (or `encode_srgb` is set and we encode here).

struct Globals {
    view_proj: mat4x4<f32>,
    light_view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // xyz: unit vector towards the sun; w: 1 if shadows are on.
    light_dir: vec4<f32>,
    // x: ground height, y: minor grid spacing, z: ground radius, w: 1 if the grid is on.
    ground: vec4<f32>,
    // xy: ground centre (x, z); z: 1 to encode sRGB in the shader; w: unused.
    ground_center: vec4<f32>,
    // xy: target size in pixels; z: shadow-map texel size in uv; w: unused.
    viewport: vec4<f32>,
    // Per material: front colour (w: 1 = orient normals to the eye), back colour.
    palette: array<vec4<f32>, 16>,
};

@group(0) @binding(0) var<uniform> g: Globals;
@group(0) @binding(1) var shadow_map: texture_depth_2d;
@group(0) @binding(2) var shadow_sampler: sampler_comparison;

const SKY_TOP: vec3<f32> = vec3<f32>(0.20, 0.30, 0.46);
const HORIZON: vec3<f32> = vec3<f32>(0.62, 0.66, 0.71);
const GROUND: vec3<f32> = vec3<f32>(0.40, 0.41, 0.43);
const SUN: vec3<f32> = vec3<f32>(1.05, 1.0, 0.92);

// ACES filmic curve, Narkowicz 2015 ("ACES Filmic Tone Mapping Curve").
fn tonemap(c: vec3<f32>) -> vec3<f32> {
    let x = c * 0.9;
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
}

// IEC 61966-2-1 sRGB transfer function, for non-sRGB targets.
fn encode(c: vec3<f32>) -> vec4<f32> {
    if (g.ground_center.z < 0.5) {
        return vec4<f32>(c, 1.0);
    }
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return vec4<f32>(select(hi, lo, c <= vec3<f32>(0.0031308)), 1.0);
}

// Fraction of sunlight reaching `world` (1 = lit): 3×3 PCF over the shadow map.
fn sunlight(world: vec3<f32>, n: vec3<f32>) -> f32 {
    let l = g.light_dir.xyz;
    // Offset along the normal facing the light, scaled by the texel size (normal-offset shadows).
    let nl = select(-n, n, dot(n, l) >= 0.0);
    let texel_world = g.viewport.z * 2.0 / max(length(g.light_view_proj[0].xyz), 1e-6);
    let p = g.light_view_proj * vec4<f32>(world + nl * texel_world * 1.5, 1.0);
    let ndc = p.xyz / p.w;
    let uv = vec2<f32>(0.5 * ndc.x + 0.5, 0.5 - 0.5 * ndc.y);
    let depth = ndc.z - 0.0015;
    var lit = 0.0;
    for (var i = -1; i <= 1; i = i + 1) {
        for (var j = -1; j <= 1; j = j + 1) {
            let o = vec2<f32>(f32(i), f32(j)) * g.viewport.z;
            lit = lit + textureSampleCompareLevel(shadow_map, shadow_sampler, uv + o, depth);
        }
    }
    let inside = all(uv > vec2<f32>(0.0)) && all(uv < vec2<f32>(1.0)) && ndc.z < 1.0;
    if (g.light_dir.w < 0.5 || !inside) {
        return 1.0;
    }
    return lit / 9.0;
}

// ---- sky: a full-screen triangle, colour by view direction ----

struct SkyOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) ndc: vec2<f32>,
};

@vertex
fn vs_sky(@builtin(vertex_index) i: u32) -> SkyOut {
    let xy = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u)) * 2.0 - 1.0;
    var out: SkyOut;
    out.clip = vec4<f32>(xy, 0.0, 1.0);
    out.ndc = xy;
    return out;
}

fn sky_colour(dir: vec3<f32>) -> vec3<f32> {
    let up = clamp(dir.y, -1.0, 1.0);
    let above = mix(HORIZON, SKY_TOP, pow(max(up, 0.0), 0.55));
    let below = HORIZON * 0.92;
    return select(below, above, up >= 0.0);
}

@fragment
fn fs_sky(in: SkyOut) -> @location(0) vec4<f32> {
    let far = g.inv_view_proj * vec4<f32>(in.ndc, 1.0, 1.0);
    let dir = normalize(far.xyz / far.w - g.eye.xyz);
    return encode(tonemap(sky_colour(dir)));
}

// ---- ground: a large square under the scene with a procedural grid ----

struct GroundOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
};

@vertex
fn vs_ground(@builtin(vertex_index) i: u32) -> GroundOut {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(-1.0, 1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(1.0, -1.0),
    );
    let c = corners[i] * g.ground.z + g.ground_center.xy;
    let world = vec3<f32>(c.x, g.ground.x, c.y);
    var out: GroundOut;
    out.clip = g.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    return out;
}

// Coverage of grid lines of `spacing` at `p`, antialiased with screen-space derivatives
// and faded out where they get denser than a few pixels.
fn grid_lines(p: vec2<f32>, spacing: f32, width: f32) -> f32 {
    let coord = p / spacing;
    let fw = max(fwidth(coord), vec2<f32>(1e-6));
    let dist = abs(fract(coord - 0.5) - 0.5) / fw;
    let line = 1.0 - min(min(dist.x, dist.y) / width, 1.0);
    let density = clamp(1.0 - (max(fw.x, fw.y) - 0.05) * 4.0, 0.0, 1.0);
    return line * density;
}

@fragment
fn fs_ground(in: GroundOut) -> @location(0) vec4<f32> {
    let minor = grid_lines(in.world.xz, g.ground.y, 1.0);
    let major = grid_lines(in.world.xz, g.ground.y * 10.0, 1.5);
    let sun = sunlight(in.world, vec3<f32>(0.0, 1.0, 0.0));
    let ndl = max(g.light_dir.y, 0.0);
    var albedo = GROUND;
    if (g.ground.w > 0.5) {
        albedo = mix(albedo, GROUND * 0.62, max(minor * 0.45, major * 0.85));
    }
    let lit = albedo * (0.42 * vec3<f32>(0.85, 0.9, 1.0) + 0.72 * SUN * ndl * sun);
    // Fade into the horizon far away, so the square has no visible edge.
    let d = length(in.world.xz - g.ground_center.xy) / g.ground.z;
    let fade = smoothstep(0.25, 0.95, d);
    let dir = normalize(in.world - g.eye.xyz);
    return encode(tonemap(mix(lit, sky_colour(vec3<f32>(dir.x, -0.0001, dir.z)) * 0.92, fade)));
}

// ---- lit surfaces: cloth (two-sided colours) and colliders ----

struct LitIn {
    @location(0) pos: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) material: u32,
    @location(3) uv: vec2<f32>,
};

struct LitOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) material: u32,
    @location(3) uv: vec2<f32>,
};

// Cells of the cloth checker across the cloth's longer side.
const CHECKER_CELLS: f32 = 16.0;

// A box-filtered checker (0 or 1, blended where a pixel covers several cells), after
// Quílez, "Filterable procedurals: checkerboard" (iquilezles.org, 2013).
fn checker(p: vec2<f32>) -> f32 {
    let w = max(fwidth(p), vec2<f32>(1e-4));
    let i = 2.0 * (abs(fract((p - 0.5 * w) * 0.5) - 0.5) - abs(fract((p + 0.5 * w) * 0.5) - 0.5)) / w;
    return 0.5 - 0.5 * i.x * i.y;
}

@vertex
fn vs_lit(in: LitIn) -> LitOut {
    var out: LitOut;
    out.clip = g.view_proj * vec4<f32>(in.pos, 1.0);
    out.world = in.pos;
    out.normal = in.normal;
    out.material = in.material;
    out.uv = in.uv;
    return out;
}

@fragment
fn fs_lit(in: LitOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let cell = checker(in.uv * CHECKER_CELLS);
    let m = min(in.material, 7u);
    let front_col = g.palette[m * 2u];
    let back_col = g.palette[m * 2u + 1u];
    var n = normalize(in.normal);
    let v = normalize(g.eye.xyz - in.world);
    var albedo = front_col.rgb;
    if (front_col.w > 0.5) {
        // Closed collider surfaces: light the side we see, whatever the winding.
        n = select(-n, n, dot(n, v) >= 0.0);
    } else if (!front) {
        n = -n;
        albedo = back_col.rgb;
    }
    if (in.uv.x > -0.5) {
        // A subtle woven checker: stretch and folds read on flat-coloured cloth.
        albedo = albedo * (1.0 - 0.12 * cell);
    }
    let l = g.light_dir.xyz;
    let sun = sunlight(in.world, n);
    // Half-Lambert wrap keeps the shaded side of folds readable; hemisphere ambient darkens
    // downward-facing creases (an occlusion-like cue).
    let ndl = max(dot(n, l), 0.0);
    let wrap = max(dot(n, l) * 0.5 + 0.5, 0.0);
    let hemi = mix(vec3<f32>(0.22, 0.21, 0.20), vec3<f32>(0.50, 0.55, 0.62), 0.5 + 0.5 * n.y);
    let fill = max(dot(n, normalize(vec3<f32>(-l.x, 0.3, -l.z))), 0.0) * 0.12;
    let h = normalize(l + v);
    let spec = pow(max(dot(n, h), 0.0), 40.0) * 0.10 * sun * step(0.0, dot(n, l));
    let sheen = pow(1.0 - max(dot(n, v), 0.0), 4.0) * 0.10;
    let light = hemi * (0.55 + 0.45 * wrap) + SUN * (ndl * sun * 0.95) + vec3<f32>(fill);
    let c = albedo * light + vec3<f32>(spec) + sheen * hemi;
    return encode(tonemap(c));
}

// ---- lines: wireframe and the drag line ----

struct LineIn {
    @location(0) pos: vec3<f32>,
    @location(1) colour: vec4<f32>,
};

struct LineOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) colour: vec4<f32>,
};

@vertex
fn vs_line(in: LineIn) -> LineOut {
    var out: LineOut;
    var clip = g.view_proj * vec4<f32>(in.pos, 1.0);
    // Pull lines slightly towards the eye so they win the depth test against their surface.
    clip.z = clip.z - 2e-4 * clip.w;
    out.clip = clip;
    out.colour = in.colour;
    return out;
}

@fragment
fn fs_line(in: LineOut) -> @location(0) vec4<f32> {
    let c = encode(in.colour.rgb);
    return vec4<f32>(c.rgb, in.colour.a);
}

// ---- points: particles and markers as screen-space discs (instanced quads) ----

struct PointIn {
    @builtin(vertex_index) corner: u32,
    @location(0) pos: vec3<f32>,
    @location(1) colour: vec4<f32>,
    @location(2) size_px: f32,
};

struct PointOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) colour: vec4<f32>,
    @location(1) uv: vec2<f32>,
};

@vertex
fn vs_point(in: PointIn) -> PointOut {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    );
    let c = corners[in.corner];
    var clip = g.view_proj * vec4<f32>(in.pos, 1.0);
    clip = vec4<f32>(clip.xy + c * in.size_px / g.viewport.xy * clip.w, clip.z - 5e-4 * clip.w, clip.w);
    var out: PointOut;
    out.clip = clip;
    out.colour = in.colour;
    out.uv = c;
    return out;
}

@fragment
fn fs_point(in: PointOut) -> @location(0) vec4<f32> {
    let r = length(in.uv);
    if (r > 1.0) {
        discard;
    }
    // A dark rim makes markers readable on any background.
    let rgb = select(in.colour.rgb, in.colour.rgb * 0.25, r > 0.72);
    let c = encode(rgb);
    return vec4<f32>(c.rgb, in.colour.a);
}
