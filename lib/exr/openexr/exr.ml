let available = Ok ()

external encode_stub :
  int -> int -> bool -> Float.Array.t -> Float.Array.t option -> string -> string
  = "lancer_exr_encode_byte" "lancer_exr_encode"

let encode ?(record = "") ~width ~height ~half ~rgb ~alpha () =
  if width < 1 || height < 1 then Error "an image needs at least one pixel"
  else if Float.Array.length rgb < 3 * width * height then
    Error "the framebuffer is smaller than the image"
  else
    match alpha with
    | Some a when Float.Array.length a < width * height ->
        Error "the alpha channel is smaller than the image"
    | _ -> (
        match encode_stub width height half rgb alpha record with
        | bytes -> Ok bytes
        | exception Failure m -> Error m)
