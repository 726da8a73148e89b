(** lancer as one library: the stable API first, then the internals, every module by its
    own name.

    The {{!stable}stable API} is what a program that renders scenes uses: load a scene
    program, get its scene at a time, render it, write or compare the image, and the
    commands' pipelines as library functions. Its names and meanings change only with a
    new minor version, noted in the changelog.

    The {{!internals}internals} are the renderer's, the job layer's and the language's own
    modules, named here for lancer's commands and tests: they change whenever lancer does,
    without notice.

    The layers, each using only those before it: [lancer.math], [lancer.diag],
    [lancer.description], [lancer.image] and [lancer.physics], [lancer.render],
    [lancer.job], [lancer.program] (which also uses the scene language, [lancer.dsl]), and
    [lancer.run] (the commands' pipelines). The package's {{!page-index}first page} has an
    example. *)

(** {1:stable The stable API} *)

(** {2 A scene program and its scenes} *)

module Program = Lancer_program.Program
module Description = Lancer_description.Description
module Settings = Lancer_description.Settings
module Camera = Lancer_description.Camera
module Light = Lancer_description.Light
module Scene = Lancer_render.Scene

(** {2 Rendering} *)

module Render = Lancer_render.Render
module Pool = Lancer_render.Pool
module Counters = Lancer_render.Counters
module Task = Lancer_render.Task
module Cancel = Lancer_diag.Cancel
module Quality = Lancer_job.Quality

(** {2 Images} *)

module Framebuffer = Lancer_image.Framebuffer
module Image = Lancer_image.Image
module Png = Lancer_image.Png
module Compare = Lancer_image.Compare

(** {2 Errors} *)

module Loc = Lancer_diag.Loc
module Diagnostic = Lancer_diag.Diagnostic
module Job_error = Lancer_job.Job_error

(** {2 Values} *)

module Vec3 = Lancer_math.Vec3
module Color = Lancer_math.Color

(** {2 The commands as library functions ([lancer.run])} *)

module Options = Lancer_run.Options
module Scene_file = Lancer_run.Scene_file
module Still_run = Lancer_run.Still_run
module Budget = Lancer_run.Budget
module Frames_run = Lancer_run.Frames_run
module Check_run = Lancer_run.Check_run
module Compare_run = Lancer_run.Compare_run
module Verify_run = Lancer_run.Verify_run
module Render_report = Lancer_run.Render_report
module Aov_run = Lancer_run.Aov_run

(** {2 The version} *)

module Version = Lancer_diag.Version

(** {1:internals Internals}

    Not part of the stable API: they change whenever lancer does. *)

(** {2 [lancer.math]} *)

module Bbox = Lancer_math.Bbox
module Hash = Lancer_math.Hash
module Probe = Lancer_math.Probe
module Ray = Lancer_math.Ray
module Floats = Lancer_math.Floats
module Transform = Lancer_math.Transform

(** {2 [lancer.diag]} *)

module Address_space = Lancer_diag.Address_space

(** {2 [lancer.description]} *)

module Features = Lancer_description.Features
module Scene_report = Lancer_description.Scene_report

(** {2 [lancer.image]} *)

module Raster = Lancer_image.Raster
module Safe_file = Lancer_image.Safe_file
module Flip = Lancer_image.Flip
module Ssim = Lancer_image.Ssim

(** {2 [lancer.physics]} *)

module Physics = Lancer_physics.Physics

(** {2 [lancer.render]} *)

module Accel = Lancer_render.Accel
module Aov = Lancer_render.Aov
module Bump = Lancer_render.Bump
module Bvh = Lancer_render.Bvh
module Compile = Lancer_render.Compile
module Cost = Lancer_render.Cost
module Frag = Lancer_render.Frag
module Material = Lancer_render.Material
module Obj_file = Lancer_render.Obj_file
module Noise = Lancer_render.Noise
module Ply = Lancer_render.Ply
module Primitive = Lancer_render.Primitive
module Shade = Lancer_render.Shade
module Shape = Lancer_render.Shape
module Texture = Lancer_render.Texture
module Trimesh = Lancer_render.Trimesh
module Walk = Lancer_render.Walk

(** {2 [lancer.job]} *)

module Animation = Lancer_job.Animation
module Checkpoint = Lancer_job.Checkpoint
module Files = Lancer_job.Files
module Provenance = Lancer_job.Provenance
module Frameset = Lancer_job.Frameset
module Overrides = Lancer_job.Overrides
module Plan = Lancer_job.Plan
module Scenes = Lancer_job.Scenes
module Still = Lancer_job.Still
module Work = Lancer_job.Work

(** {2 [lancer.run]} *)

module Output = Lancer_run.Output
module Progress = Lancer_run.Progress
