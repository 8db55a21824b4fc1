# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's settings: one PropertyGroup, stored on the Scene as `scene.exsynth`."""

import bpy
from bpy.props import (
    BoolProperty, BoolVectorProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty,
)

from . import _native

GIB = 1 << 30

# The engine's size rule for solids (the coarsest level holds one
# neighbourhood): a property's min cannot follow Levels, so the hard min is
# what one level allows and the soft min what the default 3 levels need; the
# operator checks the pair (operators/solid.py check_size).
SOLID_DEFAULT_LEVELS = _native.DEFAULT_LEVELS
# Point Texture's Custom Weights start from the engine's options for user exemplars.
_POINT_DEFAULTS = _native.point_texture_preset("default")

# The engine's solid methods (_native.SOLID_METHODS); the enum's identifiers
# are the names upper-cased, the job passes them back lower-cased.
_SOLID_METHOD_TEXT = {
    "optimization": ("Optimization", "Texture optimisation of voxel values (Kopf et al. 2007), guided by "
                     "the Feature Weight: whole stones on any cut, softer slices; takes the Python API's "
                     "constraint volume"),
    "coordinates": ("Coordinates", "Exemplar coordinates with crossbar candidates (Dong et al. 2008): every "
                    "voxel is a texel of the exemplar: crisper slices, but square blocks with straight seams "
                    "on oblique cuts"),
}
SOLID_METHOD_ITEMS = tuple((m.upper(), *_SOLID_METHOD_TEXT.get(m, (m.title(), m))) for m in _native.SOLID_METHODS)

# The engine's rotate_exemplar choices (_native.ROTATE_EXEMPLAR_CHOICES), likewise.
_ROTATE_EXEMPLAR_TEXT = {
    "auto": ("Auto", "Turn the exemplar when its features are round (the engine measures their stretch); "
             "wood grain, bricks and bedded stone keep their direction"),
    "on": ("On", "Always turn it: slower for exemplars under 256 pixels (analysed in four turns: about 1.4x the "
           "time at 128 voxels; larger ones turn their quadrants, at no extra cost); wrong for anything that runs "
           "one way"),
    "off": ("Off", "Never turn it"),
}
ROTATE_EXEMPLAR_ITEMS = tuple((c.upper(), *_ROTATE_EXEMPLAR_TEXT.get(c, (c.title(), c)))
                              for c in _native.ROTATE_EXEMPLAR_CHOICES)

# The engine's interpolations for baking (_native.INTERPOLATION_CHOICES), likewise.
_INTERPOLATION_TEXT = {
    "cubic": ("Cubic", "Tricubic, kept within the surrounding voxels' range: voxel-sized grain and cracks "
              "keep their contrast, no halos"),
    "linear": ("Linear", "Trilinear: softer; voxel-sized detail loses about half its contrast"),
}
INTERPOLATION_ITEMS = tuple((c.upper(), *_INTERPOLATION_TEXT.get(c, (c.title(), c)))
                            for c in _native.INTERPOLATION_CHOICES)

# The direction-field presets (Direction Field and Geometric Texture).
FIELD_PRESET_ITEMS = (
    ('AROUND_AXIS', "Around Axis", "Circles around the axis through the mesh's centre"),
    ('ALONG_AXIS', "Along Axis", "The axis, laid flat onto the surface"),
    ('ALONG_CURVE', "Along Curve", "The direction of the nearest point of a curve object"),
)


def _overlay_sync(settings, context):
    from . import overlay  # the overlay module imports gpu helpers: load it on first use

    overlay.sync(settings, context)


class ExSynthSettings(bpy.types.PropertyGroup):
    resolution: IntProperty(
        name="Resolution",
        description="Voxels along the longest side of the object's bounding box",
        default=128, min=8, max=1024, soft_max=512,
    )
    padding: IntProperty(
        name="Padding",
        description="Empty voxels added around the object on every side, so the surface "
        "and its distance field do not touch the grid border",
        default=2, min=0, max=64,
    )
    supersample: IntProperty(
        name="Supersample",
        description="Sub-rays per voxel edge used to measure how much of a surface voxel "
        "is inside (higher: smoother density, slower)",
        default=2, min=1, max=8,
    )
    make_mesh: BoolProperty(
        name="Make Mesh",
        description="Also rebuild a mesh from the voxels (the zero level of the signed distance)",
        default=True,
    )
    seed: IntProperty(
        name="Seed",
        description="Random seed (the same inputs and seed give the same result)",
        default=0, min=0,
    )
    memory_budget_gib: FloatProperty(
        name="Memory Budget",
        description="Refuse a job whose estimated peak memory exceeds this many GiB "
        "(checked before anything is allocated)",
        default=8.0, min=0.001, max=1024.0, soft_max=64.0, precision=3, unit='NONE',
    )

    # ---- Solid Texture ------------------------------------------------------
    solid_exemplar: PointerProperty(
        name="Exemplar",
        description="The 2D texture the solid should look like on every slice "
        "(any image: packed or on disk, 8/16-bit or float)",
        type=bpy.types.Image,
    )
    solid_exemplar_y: PointerProperty(
        name="Exemplar Y",
        description="Optional: what slices across the Y axis (the XZ plane) should look like; "
        "empty uses the main exemplar",
        type=bpy.types.Image,
    )
    solid_exemplar_z: PointerProperty(
        name="Exemplar Z",
        description="Optional: what slices across the Z axis (the XY plane) should look like; "
        "empty uses the main exemplar",
        type=bpy.types.Image,
    )
    solid_use_alpha: BoolProperty(
        name="Alpha",
        description="Synthesize the exemplar's alpha as a fourth channel (kept in the images and "
        "as the Volume's 'alpha' grid)",
        default=False,
    )
    solid_size: IntProperty(
        name="Size",
        description="Voxels along each edge of the solid (it is Size × Size × Size and tiles); "
        f"at least {_native.min_texture_size(SOLID_DEFAULT_LEVELS)} with {SOLID_DEFAULT_LEVELS} Levels, "
        f"{_native.min_texture_size(1)} with 1",
        default=_native.SOLID_DEFAULT_SIZE, min=_native.min_texture_size(1),
        soft_min=_native.min_texture_size(SOLID_DEFAULT_LEVELS),
        max=_native.SOLID_MAX_SIZE, soft_max=256,
    )
    solid_levels: IntProperty(
        name="Levels",
        description="Coarse-to-fine levels; the coarsest (Size / 2^(Levels-1)) and the exemplar at "
        "that level must be at least 8 pixels across",
        default=SOLID_DEFAULT_LEVELS, min=1, max=_native.MAX_LEVELS, soft_max=6,
    )
    solid_iterations: IntProperty(
        name="Iterations",
        description="Optimisation rounds per level (more: closer to the exemplar, slower)",
        default=_native.DEFAULT_ITERATIONS, min=1, max=_native.MAX_ITERATIONS, soft_max=20,
    )
    solid_method: EnumProperty(
        name="Method",
        description="How the solid is synthesized",
        items=SOLID_METHOD_ITEMS,
        default=_native.SOLID_DEFAULT_METHOD.upper(),
    )
    solid_feature_weight: FloatProperty(
        name="Feature Weight",
        description="How much the distance to the edges of the exemplar's dark features (cracks, mortar, "
        "veins) guides the Optimization method's matching: higher keeps them crisper and whole, 0 = colours "
        "only. The Coordinates method ignores it",
        default=_native.SOLID_DEFAULT_FEATURE_WEIGHT, min=0.0, max=100.0, soft_max=8.0,
    )
    solid_feature_threshold: FloatProperty(
        name="Feature Threshold",
        description="Which dark pixels of the exemplar count as features for Feature Weight, in the "
        "exemplar's brightness standard deviations below their neighbourhood: 0 = any darker pixel "
        "(soft, isotropic cells); about 1 = only deep cracks and mortar (a crisper crack network; with "
        "round cells, keep Rotate Exemplar on Auto or On, or they line up along one diagonal). The "
        "Coordinates method ignores it",
        default=_native.SOLID_DEFAULT_FEATURE_THRESHOLD, min=0.0, max=_native.SOLID_MAX_FEATURE_THRESHOLD,
        soft_max=2.0,
    )
    solid_feature_scale: IntProperty(
        name="Feature Scale",
        description="How far into a stone or cell, in exemplar pixels, the Optimization method's feature "
        "distance still grows: larger tells a stone's middle from its rim and keeps round stones whole "
        "(crackedground at 16), but can line other textures up as sheets; 0 = the neighbourhood's size (8). "
        "The Coordinates method ignores it",
        default=_native.SOLID_DEFAULT_FEATURE_SCALE, min=0, max=_native.SOLID_MAX_FEATURE_SCALE, soft_max=32,
    )
    solid_rotate_exemplar: EnumProperty(
        name="Rotate Exemplar",
        description="Also match the exemplar turned by 90, 180 and 270 degrees, for textures with no preferred "
        "direction (cracks, cells, pebbles), whose cells otherwise line up along one diagonal. The Coordinates "
        "method ignores it",
        items=ROTATE_EXEMPLAR_ITEMS,
        default=_native.SOLID_DEFAULT_ROTATE_EXEMPLAR.upper(),
    )
    solid_histogram_values: FloatProperty(
        name="Histogram Values",
        description="How strongly the Optimization method picks each voxel's exemplar colour so that the solid "
        "has the exemplar's share of dark and light (cracks, mortar, light stones): higher matches contrast "
        "closer, above 0.5 it oscillates; 0 = each voxel takes its best-matching window's colour. The "
        "Coordinates method ignores it",
        default=_native.SOLID_DEFAULT_HISTOGRAM_VALUES, min=0.0, max=100.0, soft_max=1.0,
    )
    solid_structure_sigma: FloatProperty(
        name="Structure Blur",
        description="The Optimization method's split, in voxels: shapes larger than this (cells, stones, cracks' "
        "outlines) come from the optimiser's smooth average, finer grain from the exemplar's own colours, then "
        "the colours are matched to the exemplar's. Clearer cells; 0 = exemplar colours only. The Coordinates "
        "method ignores it",
        default=_native.SOLID_DEFAULT_STRUCTURE_SIGMA, min=0.0, max=_native.SOLID_MAX_STRUCTURE_SIGMA,
        soft_max=3.0,
    )
    solid_scale: FloatProperty(
        name="Scale",
        description="Edge length of one tile of the solid, in the units of the solid's Volume object "
        "(world units when it is created); the texture repeats beyond it",
        default=1.0, min=1e-4, soft_max=100.0, subtype='DISTANCE', unit='LENGTH',
    )
    solid_bake_target: EnumProperty(
        name="Bake To",
        description="Where the solid's colours go on each selected mesh",
        items=(
            ('IMAGE', "Image Texture", "A new image over the mesh's UV map (made with Smart UV Project "
             "when it has none), shown by a new material"),
            ('ATTRIBUTE', "Color Attribute", "A face-corner colour attribute 'solid' (no UVs needed; "
             "detail limited by the mesh's density)"),
        ),
        default='IMAGE',
    )
    solid_bake_resolution: IntProperty(
        name="Resolution",
        description="Width and height of each baked image, in pixels",
        default=_native.BAKE_DEFAULT_SIZE, min=16, max=_native.BAKE_MAX_SIZE, soft_max=8192,
    )
    solid_bake_interpolation: EnumProperty(
        name="Interpolation",
        description="How each texel or face corner reads the solid between its voxels",
        items=INTERPOLATION_ITEMS,
        default=_native.DEFAULT_INTERPOLATION.upper(),
    )
    solid_new_uvs: BoolProperty(
        name="New UV Map",
        description="Unwrap with Smart UV Project into a UV map 'SolidUV' even when the mesh has "
        "UV maps (e.g. after a Boolean cut, whose new faces have no useful UVs); a mesh without "
        "any always gets one, 'UVMap'",
        default=False,
    )
    solid_volume: PointerProperty(
        name="Solid",
        description="The solid to bake from: a Volume object made by Solid Texture (its .vdb and "
        "its place in the scene define the texture)",
        type=bpy.types.Object,
        poll=lambda self, obj: obj.type == 'VOLUME',
    )

    # ---- Direction Field ----------------------------------------------------
    field_mode: EnumProperty(
        name="Mode",
        description="How the direction field is made",
        items=(
            ('PRESET', "Preset", "A field from a simple rule: around or along an axis, or along a curve"),
            ('DIFFUSE', "Diffuse Painted", "Spread the vectors painted into a Vector point attribute "
             "(zero = free) over the whole surface"),
        ),
        default='PRESET',
    )
    field_preset: EnumProperty(
        name="Preset",
        description="The rule the field follows",
        items=FIELD_PRESET_ITEMS,
        default='AROUND_AXIS',
    )
    field_axis: EnumProperty(
        name="Axis",
        description="The axis, in the mesh's own (local) coordinates",
        items=(('X', "X", "The mesh's local X axis"), ('Y', "Y", "The mesh's local Y axis"),
               ('Z', "Z", "The mesh's local Z axis")),
        default='Z',
    )
    field_curve: PointerProperty(
        name="Curve",
        description="The curve the field follows (its first and only spline, as evaluated)",
        type=bpy.types.Object,
        poll=lambda self, obj: obj.type == 'CURVE',
    )
    field_paint_attribute: StringProperty(
        name="Painted",
        description="The Vector attribute on the Vertex domain holding painted directions "
        "(zero vectors are free and get filled in)",
        default="exsynth_paint",
    )
    # Painting (Paint Direction Field) and the field overlay.
    field_brush_mode: EnumProperty(
        name="Brush",
        description="What a stroke does (keys P, E, C while painting)",
        items=(('PAINT', "Paint", "Set the directions under the brush to the stroke's"),
               ('ERASE', "Erase", "Remove the painted directions under the brush (the field is diffused again)"),
               ('COMB', "Comb", "Drag the existing directions under the brush along the stroke, a little per sample")),
        default='PAINT',
    )
    field_brush_radius: IntProperty(
        name="Radius", description="Brush radius in screen pixels (keys [ and ] while painting)",
        default=40, min=1, max=1000, soft_max=300, subtype='PIXEL',
    )
    field_brush_strength: FloatProperty(
        name="Strength", description="How far a sample turns the directions at the brush centre (1: fully)",
        default=1.0, min=0.01, max=1.0,
    )
    field_mirror: BoolVectorProperty(
        name="Mirror", description="Also paint the stroke mirrored across the mesh's local X, Y or Z axis "
        "(keys X, Y, Z while painting)", size=3, subtype='XYZ', default=(False, False, False),
    )
    field_overlay: BoolProperty(
        name="Show Field", description="Draw the active mesh's 'exsynth_field' in the viewport as short "
        "strokes (dark tail, yellow head), singular points red, clashing neighbours orange",
        default=False, update=_overlay_sync,
    )
    field_overlay_max_strokes: IntProperty(
        name="Strokes", description="At most this many strokes (every n-th vertex)",
        default=4000, min=10, max=500000, soft_max=50000,
    )
    field_overlay_length: FloatProperty(
        name="Length", description="Stroke length as a fraction of the spacing between strokes",
        default=0.8, min=0.05, max=10.0, soft_max=3.0,
    )
    field_overlay_singularities: BoolProperty(
        name="Singularities", description="Mark where the field is undefined or turns around a point (red) "
        "and where neighbouring directions clash (orange)", default=True,
    )

    # ---- Geometric Texture ---------------------------------------------------
    geo_pair_source: EnumProperty(
        name="Pair Source",
        description="Where the exemplar pair A → A′ comes from",
        items=(
            ('BUILTIN', "Built-in", "A built-in pair: spikes, pits, holes, grooves or dilation"),
            ('OBJECTS', "Objects", "Two mesh objects you made: A, and A′ with the change modelled on it"),
        ),
        default='BUILTIN',
    )
    geo_preset: EnumProperty(
        name="Pair",
        description="The built-in exemplar pair A → A′ whose change is applied to the active mesh",
        items=(
            ('SPIKES', "Spikes", "Flat slab → slab with cones: spikes grow out of the surface"),
            ('PITS', "Pits", "Flat slab → slab with round dents in rows along the field"),
            ('HOLES', "Holes", "Flat slab → slab with holes through it (shows on thin parts)"),
            ('GROOVES', "Grooves", "Cylinder → grooved cylinder: grooves run along the direction field"),
            ('DILATE', "Dilate", "Sphere → larger sphere: the whole surface moves out"),
        ),
        default='SPIKES',
    )
    geo_a: PointerProperty(
        name="A",
        description="The exemplar before the change (a mesh with faces, in the same units as the "
        "active mesh: its features are copied at their world size)",
        type=bpy.types.Object,
        poll=lambda self, obj: obj.type == 'MESH',
    )
    geo_a_prime: PointerProperty(
        name="A′",
        description="The exemplar after the change: a copy of A (Shift+D; it may stand beside A) with "
        "the geometry you want copied (bumps, grooves, ...) modelled on it. It is compared with A in "
        "its own coordinates placed with A's transform",
        type=bpy.types.Object,
        poll=lambda self, obj: obj.type == 'MESH',
    )
    geo_a_selected_only: BoolProperty(
        name="Selected Faces of A",
        description="Learn only from the faces selected on A (select them in Edit Mode, then go back "
        "to Object Mode): A can then be a whole model and A′ its copy with the change modelled on "
        "those faces; the rest of the model teaches nothing",
        default=False,
    )
    geo_field_preset: EnumProperty(
        name="Field",
        description="The direction the pattern follows on a mesh without an 'exsynth_field' "
        "attribute (a mesh with one uses it: Direction Field makes it)",
        items=FIELD_PRESET_ITEMS,
        default='AROUND_AXIS',
    )
    geo_field_axis: EnumProperty(
        name="Axis",
        description="The field preset's axis, in world coordinates",
        items=(('X', "X", "The world X axis"), ('Y', "Y", "The world Y axis"),
               ('Z', "Z", "The world Z axis (up)")),
        default='Z',
    )
    geo_field_curve: PointerProperty(
        name="Curve",
        description="The curve the field follows (its first and only spline, as evaluated)",
        type=bpy.types.Object,
        poll=lambda self, obj: obj.type == 'CURVE',
    )
    geo_resolution: IntProperty(
        name="Resolution",
        description="Voxels along the longest side of the mesh's bounding box (time and memory grow "
        "with its cube). With a built-in pair and Fit to Model, the least: a small pattern raises it "
        "until the pair has the voxels its features need (the panel shows the value used)",
        default=128, min=16, max=512, soft_max=256,
    )
    geo_pattern_fit: BoolProperty(
        name="Fit to Model",
        description="Built-in pairs: size the pattern from the mesh's own thickness (twice the median "
        "diameter of the balls that fit inside it at its surface), so thin parts get features that "
        "fit them; the size is shown in the panel and in the viewport. Off: set Pattern Size by hand",
        default=True,
    )
    geo_pattern_scale: FloatProperty(
        name="Pattern Size",
        description="Built-in pairs, Fit to Model off: how much of the mesh one exemplar cube covers, "
        "as a fraction of its longest side (smaller: smaller, denser features). The pair is made at "
        "Resolution × Pattern Size voxels, 8 to 512",
        default=0.5, min=0.05, max=4.0, soft_max=2.0, precision=2,
    )
    geo_show_pattern: BoolProperty(
        name="Show Pattern Size",
        description="Draw a wire sphere of the pattern's size at the active mesh in the 3D viewport",
        default=True,
    )
    geo_dilation: FloatProperty(
        name="Dilation",
        description=f"Dilate: how much larger A′'s sphere is than A's (radius "
        f"{_native.PAIR_DEFAULTS['sphere_radius']:g} in the exemplar's [-1, 1] cube; 0.15 moves the surface "
        "out by 15 % of half the pattern size)",
        default=_native.PAIR_DEFAULTS["dilation"], min=0.02, max=0.4, precision=3,
    )
    geo_spike_height: FloatProperty(
        name="Spike Height",
        description="Spikes: the cones' height in the exemplar's [-1, 1] cube",
        default=_native.PAIR_DEFAULTS["feature_height"], min=0.05, max=0.5, precision=3,
    )
    geo_make_volume: BoolProperty(
        name="Make Volume",
        description="Also add a Volume object with the result's signed distance (grid 'sdf') and "
        "a density grid",
        default=False,
    )

    # ---- Point Texture ------------------------------------------------------
    pts_exemplar_source: EnumProperty(
        name="Exemplar",
        description="The geometry texture to grow: oriented points over a reference plane (z up)",
        items=(
            ('BUILTIN', "Built-in", "A generated geometry texture (bumps, chainmail, weave, flowers), 1 × 1 unit"),
            ('OBJECT', "Object", "A mesh object, sampled evenly; its x, y bounds less 15 % per side are the box"),
            ('SELECTED', "Selected Faces", "The faces selected on a mesh object, sampled evenly"),
            ('FILE', "File", "A point file with normals: .ply (nx ny nz), .xyz or .pwn"),
        ),
        default='BUILTIN',
    )
    pts_preset: EnumProperty(
        name="Texture",
        description="The built-in geometry texture",
        items=(('BUMPS', "Bumps", "Round bumps on a height field"),
               ('CHAINMAIL', "Chainmail", "Interlocked rings (European 4-in-1)"),
               ('WEAVE', "Weave", "Over-under tubes"),
               ('FLOWERS', "Flowers", "Small flowers on stems over the ground")),
        default='CHAINMAIL',
    )
    pts_object: PointerProperty(
        name="Object", description="The mesh to sample the exemplar from (world units)",
        type=bpy.types.Object, poll=lambda self, obj: obj.type == 'MESH',
    )
    pts_file: StringProperty(name="File", description="A .ply with normals, .xyz or .pwn", subtype='FILE_PATH')
    pts_density: FloatProperty(
        name="Density", description="Points per unit of surface area of the exemplar (more: finer, slower)",
        default=_native.POINTS_DEFAULT_DENSITY, min=10.0, soft_max=200000.0,
    )
    pts_output: EnumProperty(
        name="Output", description="Where the texture grows",
        items=(('PLANE', "Plane", "Over a W × D area of the reference plane, at the 3D cursor"),
               ('TARGET', "Target Mesh", "Over the surface of a mesh, following its direction field")),
        default='PLANE',
    )
    pts_width: FloatProperty(name="Width", description="Output size along x, exemplar units", default=3.0,
                             min=0.05, soft_max=50.0)
    pts_depth: FloatProperty(name="Depth", description="Output size along y, exemplar units", default=3.0,
                             min=0.05, soft_max=50.0)
    pts_target: PointerProperty(
        name="Target", description="The mesh to cover (its 'exsynth_field' attribute orients the texture, "
        "otherwise the field preset)", type=bpy.types.Object, poll=lambda self, obj: obj.type == 'MESH',
    )
    pts_scale: FloatProperty(name="Scale", description="Target units per exemplar unit; 0 = chosen from the "
                             "target's area for a job of about half a minute (the panel shows the estimate)",
                             default=0.0, min=0.0, soft_max=10.0)
    pts_field_preset: EnumProperty(name="Field", description="The direction the texture's x axis follows "
                                   "on a target without an 'exsynth_field' attribute",
                                   items=FIELD_PRESET_ITEMS, default='AROUND_AXIS')
    pts_field_axis: EnumProperty(name="Axis", description="The field preset's axis, world coordinates",
                                 items=(('X', "X", ""), ('Y', "Y", ""), ('Z', "Z", "")), default='Z')
    pts_field_curve: PointerProperty(name="Curve", description="The curve the field follows",
                                     type=bpy.types.Object, poll=lambda self, obj: obj.type == 'CURVE')
    pts_patch_size: FloatProperty(name="Patch Size", description="Side of a patch, exemplar units (must fit in "
                                  "the exemplar with room to spare)", default=0.5, min=0.01, soft_max=5.0)
    pts_make_mesh: BoolProperty(name="Make Surface", description="Also add a mesh made from the points "
                                "(OpenVDB particles to level set to mesh)", default=False)
    pts_custom_weights: BoolProperty(name="Custom Weights", description="Use the weights below instead of "
                                     "the texture's preset", default=False)
    pts_extra: FloatProperty(name="Overlap", description="The overlap E as a fraction of the patch",
                             default=_POINT_DEFAULTS["extra"], min=0.1, max=0.5)
    pts_epsilon: FloatProperty(name="Epsilon", description="Candidates within (1 + epsilon) of the best "
                               "are picked at random", default=_POINT_DEFAULTS["epsilon"], min=0.0, soft_max=1.0)
    pts_w_p: FloatProperty(name="Position", description="Pairing: weight of the squared position difference "
                           "(in point spacings)", default=_POINT_DEFAULTS["w_p"], min=0.0)
    pts_w_n: FloatProperty(name="Normal", description="Pairing: weight of the normal difference, (1 - cos) / 2",
                           default=_POINT_DEFAULTS["w_n"], min=0.0)
    pts_w_v: FloatProperty(name="Variation", description="Pairing: weight of the squared surface-variation "
                           "difference", default=_POINT_DEFAULTS["w_v"], min=0.0)
    pts_w_l: FloatProperty(name="Length", description="Coherence: weight of the displacement's length "
                           "difference from its neighbours' (in point spacings)",
                           default=_POINT_DEFAULTS["w_l"], min=0.0)
    pts_w_d: FloatProperty(name="Direction", description="Coherence: weight of the displacement's direction "
                           "difference from its neighbours', (1 - cos) / 2", default=_POINT_DEFAULTS["w_d"], min=0.0)
    # ---- Surface Texture (texture synthesis on the subdivision surface) ----
    surface_exemplar: PointerProperty(
        name="Exemplar", description="The image whose pattern covers the surface", type=bpy.types.Image,
    )
    surface_height: PointerProperty(
        name="Height",
        description="Optional height image of the same size, synthesized with the colour: the result "
        "mesh is displaced along its normal by it (real geometry)",
        type=bpy.types.Image,
    )
    surface_use_alpha: BoolProperty(
        name="Alpha", description="Synthesize the exemplar's alpha too and wire it to the material's Alpha",
        default=False,
    )
    surface_method: EnumProperty(
        name="Method",
        items=(('COHERENT', "Coherent", "One pass copying coherent patches (Ashikhmin): fastest"),
               ('MULTISCALE', "Multiscale", "Gaussian pyramids, two passes per level (Wei-Levoy)")),
        default='COHERENT',
    )
    surface_size_mode: EnumProperty(
        name="Texels",
        items=(('DENSITY', "Density", "Texels per unit of surface length"),
               ('FACE', "Per Face", "The same map size on every face")),
        default='DENSITY',
    )
    surface_density: FloatProperty(
        name="Texels per Unit", description="Texels per unit of surface length (world units)",
        default=64.0, min=1.0, soft_max=2048.0,
    )
    surface_face_resolution: IntProperty(
        name="Face Resolution", description="Texels along each face map's side (an n-gon has n maps)",
        default=_native.SURFACE_DEFAULT_FACE_RESOLUTION, min=2, max=_native.SURFACE_MAX_FACE_RESOLUTION,
    )
    surface_exemplar_scale: FloatProperty(
        name="Exemplar Scale", description="Exemplar pixels per texel: larger makes the pattern smaller",
        default=1.0, min=0.05, max=16.0,
    )
    surface_field: EnumProperty(
        name="Field",
        description="Which way the pattern runs on a mesh without an 'exsynth_field' attribute (a mesh "
        "with one uses it)",
        items=(('SMOOTH', "Smooth", "A smooth field from the axis, by optimisation"),
               ('AROUND_AXIS', "Around Axis", "Circles around the axis"),
               ('ALONG_AXIS', "Along Axis", "The axis laid onto the surface")),
        default='SMOOTH',
    )
    surface_axis: EnumProperty(
        name="Axis", items=(('X', "X", ""), ('Y', "Y", ""), ('Z', "Z", "")), default='Z',
    )
    surface_height_scale: FloatProperty(
        name="Height Scale", description="Displacement (world units) per unit of height around 0.5",
        default=0.02, min=0.0, soft_max=1.0, precision=3,
    )
    surface_segments: IntProperty(
        name="Mesh Detail",
        description="Quads along each n-gon sub-face of the result (quads get twice as many); the "
        "vertices of Blender's Subdivision level L are those of 2^(L-1)",
        default=_native.SURFACE_DEFAULT_SEGMENTS, min=1, max=_native.SURFACE_MAX_SEGMENTS, soft_max=32,
    )

    @property
    def memory_budget_bytes(self) -> int:
        return max(1, int(self.memory_budget_gib * GIB))


CLASSES = (ExSynthSettings,)


def attach():
    bpy.types.Scene.exsynth = PointerProperty(type=ExSynthSettings)


def detach():
    if hasattr(bpy.types.Scene, "exsynth"):
        del bpy.types.Scene.exsynth
