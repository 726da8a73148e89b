(** lancer as one library: every module of its layers, by its own name.

    The layers, each using only those before it: [lancer.math], [lancer.diag],
    [lancer.description], [lancer.image] and [lancer.physics], [lancer.render],
    [lancer.job], [lancer.program] (which also uses the scene language), and [lancer.run]
    (the commands' pipelines as library functions). *)

(** {1 [lancer.math]} *)

module Bbox = Lancer_math.Bbox
module Color = Lancer_math.Color
module Hash = Lancer_math.Hash
module Probe = Lancer_math.Probe
module Ray = Lancer_math.Ray
module Floats = Lancer_math.Floats
module Transform = Lancer_math.Transform
module Vec3 = Lancer_math.Vec3

(** {1 [lancer.diag]} *)

module Address_space = Lancer_diag.Address_space
module Cancel = Lancer_diag.Cancel
module Diagnostic = Lancer_diag.Diagnostic
module Loc = Lancer_diag.Loc

(** {1 [lancer.description]} *)

module Camera = Lancer_description.Camera
module Description = Lancer_description.Description
module Features = Lancer_description.Features
module Light = Lancer_description.Light
module Scene_report = Lancer_description.Scene_report
module Settings = Lancer_description.Settings

(** {1 [lancer.image]} *)

module Compare = Lancer_image.Compare
module Flip = Lancer_image.Flip
module Image = Lancer_image.Image
module Png = Lancer_image.Png
module Raster = Lancer_image.Raster
module Safe_file = Lancer_image.Safe_file
module Ssim = Lancer_image.Ssim

(** {1 [lancer.physics]} *)

module Physics = Lancer_physics.Physics

(** {1 [lancer.render]} *)

module Accel = Lancer_render.Accel
module Bump = Lancer_render.Bump
module Bvh = Lancer_render.Bvh
module Compile = Lancer_render.Compile
module Cost = Lancer_render.Cost
module Frag = Lancer_render.Frag
module Material = Lancer_render.Material
module Obj_file = Lancer_render.Obj_file
module Noise = Lancer_render.Noise
module Ply = Lancer_render.Ply
module Pool = Lancer_render.Pool
module Primitive = Lancer_render.Primitive
module Render = Lancer_render.Render
module Scene = Lancer_render.Scene
module Shade = Lancer_render.Shade
module Shape = Lancer_render.Shape
module Stats = Lancer_render.Stats
module Texture = Lancer_render.Texture
module Trimesh = Lancer_render.Trimesh
module Walk = Lancer_render.Walk

(** {1 [lancer.job]} *)

module Animation = Lancer_job.Animation
module Checkpoint = Lancer_job.Checkpoint
module Files = Lancer_job.Files
module Frameset = Lancer_job.Frameset
module Job_error = Lancer_job.Job_error
module Overrides = Lancer_job.Overrides
module Plan = Lancer_job.Plan
module Quality = Lancer_job.Quality
module Source = Lancer_job.Source
module Still = Lancer_job.Still
module Work = Lancer_job.Work

(** {1 The version} *)

module Version = Version

(** {1 [lancer.program]} *)

module Program = Lancer_program.Program

(** {1 [lancer.run]} *)

module Check_run = Lancer_run.Check_run
module Compare_run = Lancer_run.Compare_run
module Frames_run = Lancer_run.Frames_run
module Options = Lancer_run.Options
module Output = Lancer_run.Output
module Progress = Lancer_run.Progress
module Render_report = Lancer_run.Render_report
module Scene_file = Lancer_run.Scene_file
module Still_run = Lancer_run.Still_run
