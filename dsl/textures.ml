module D = Description
open Value

let ( let* ) = Result.bind
let at t field_loc = if t.tname = "image" then t.tloc else field_loc

(* The image file of an [image(…)] texture or bump map, relative to the scene file that
   names it; the renderer reads it (and reports a problem with it at the call). *)
let image_file ~use t =
  match t.targs with
  | VStr p :: _ ->
      let im = { D.written = p; path = Loc.relative_to t.tloc.file p; at = t.tloc } in
      use (D.Picture im);
      Ok im
  | _ -> Error Msg.image_file

let color_map t =
  let entries =
    List.filter_map
      (function VPair (VNum x, VVec c) -> Some (x, Color.of_vec3 c) | _ -> None)
      t.targs
  in
  match D.color_map_problem entries with Some m -> Error m | None -> Ok entries

let texture ~use t =
  let arg i = List.nth t.targs i in
  let c i =
    match arg i with
    | VVec v -> Ok (Color.of_vec3 v)
    | v -> Error (Msg.argument (i + 1) t.tname "a colour (r, g, b)" (ty v))
  in
  let size i what =
    match arg i with
    | VNum s when s >= 1e-150 && s <= 1e150 -> Ok s
    | VNum s -> Error (Msg.texture_size what t.tname s)
    | v -> Error (Msg.argument (i + 1) t.tname "a number" (ty v))
  in
  let solid mk =
    let* c1 = c 0 in
    let* c2 = c 1 in
    let* s =
      size 2 (if t.tname = "checker" || t.tname = "stripes" then "size" else "scale")
    in
    Ok (mk c1 c2 s)
  in
  match (t.tname, t.targs) with
  | "checker", _ -> solid (fun c1 c2 size -> D.Checker { c1; c2; size })
  | "stripes", _ -> solid (fun c1 c2 size -> D.Stripes { c1; c2; size })
  | ("noise" | "marble" | "wood"), [ VTex ({ tname = "color_map"; _ } as cm); _ ] ->
      let* scale = size 1 "scale" in
      let* map = color_map cm in
      let pattern =
        match t.tname with
        | "noise" -> D.Noise_pattern scale
        | "marble" -> D.Marble_pattern scale
        | _ -> D.Wood_pattern scale
      in
      Ok (D.Mapped { pattern; map })
  | ("marble" | "wood"), [ _; _ ] -> Error (Msg.marble_arguments t.tname)
  | "noise", [ _; _; _ ] -> solid (fun c1 c2 scale -> D.Noise { c1; c2; scale })
  | "marble", _ -> solid (fun c1 c2 scale -> D.Marble { c1; c2; scale })
  | "wood", _ -> solid (fun c1 c2 scale -> D.Wood { c1; c2; scale })
  | "noise", _ -> Error Msg.noise_texture
  | "gradient", [ VVec axis; VTex ({ tname = "color_map"; _ } as cm) ] ->
      if not (Vec3.max_abs axis > 0. && Vec3.max_abs axis <= 1e150) then
        Error Msg.gradient_axis
      else
        let* map = color_map cm in
        Ok (D.Gradient { axis; map })
  | "gradient", _ -> Error Msg.gradient_texture
  | "color_map", _ -> Error Msg.color_map_texture
  | "image", [ VStr _; VNum scale ] when scale >= 1e-150 && scale <= 1e150 ->
      let* image = image_file ~use t in
      Ok (D.Image { image; scale })
  | "image", [ VStr _; VNum scale ] -> Error (Msg.image_scale scale)
  | "image", [ VStr _ ] -> Error Msg.image_needs_scale
  | "image", _ -> Error Msg.image_arguments
  | _ -> Error (Msg.not_a_texture t.tname)

let bump ~use t =
  match (t.tname, t.targs) with
  | "noise", [ VNum scale; VNum amount ] ->
      if not (scale >= 1e-150 && scale <= 1e150) then Error (Msg.noise_bump_scale scale)
      else if not (Float.abs amount <= 1e150) then Error Msg.noise_bump_amount
      else Ok (D.Noise_bump { scale; amount })
  | "noise", [ _; _ ] -> Error Msg.noise_bump_arguments
  | "image", [ VStr _; VNum amount ] when Float.abs amount <= 1e150 ->
      Result.map (fun image -> D.Image_bump { image; amount }) (image_file ~use t)
  | "image", _ -> Error Msg.image_bump_arguments
  | _ -> Error (Msg.not_a_bump t.tname)
