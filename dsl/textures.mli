(** The values of texture-like built-ins ([checker(…)], [gradient(…)], [image(…)],
    [noise(…)], …) read where a material uses them, as its texture or its bump map. What
    the call's arguments are is checked here, where what the value is for is known (a
    [noise] of two numbers is a bump map, of two colours and a scale a texture). Pure: an
    image is named, not read. *)

module D = Description

val texture : use:(D.file_use -> unit) -> Value.tex -> (D.texture, string) result
(** [use] is told the image file of an [image(…)] texture. *)

val bump : use:(D.file_use -> unit) -> Value.tex -> (D.bump, string) result

val at : Value.tex -> Loc.t -> Loc.t
(** Where a problem of the value is shown, given the field's place: an [image(…)]'s at the
    call (which names the file, perhaps a [let] away), any other's at the field. *)
