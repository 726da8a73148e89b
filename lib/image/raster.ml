let max_pixels = 16384 * 16384

type t = { width : int; height : int; channels : int; depth : int; samples : Bytes.t }

let make ~width ~height ~channels ~depth samples =
  if channels < 1 || channels > 4 then invalid_arg "Raster.make: channels must be 1 to 4";
  if depth <> 8 && depth <> 16 then invalid_arg "Raster.make: depth must be 8 or 16";
  if Bytes.length samples <> width * height * channels * (depth / 8) then
    invalid_arg "Raster.make: wrong number of samples";
  { width; height; channels; depth; samples }

let max_value r = if r.depth = 16 then 65535 else 255

let get r i j c =
  let k = (((j * r.width) + i) * r.channels) + c in
  if r.depth = 8 then Bytes.get_uint8 r.samples k
  else Bytes.get_uint16_be r.samples (2 * k)

let to_rgb8 r =
  if r.channels = 3 && r.depth = 8 then Bytes.copy r.samples
  else
    let n = r.width * r.height in
    let out = Bytes.create (3 * n) in
    let to8 v = if r.depth = 8 then v else ((v * 255) + 32767) / 65535 in
    let color = r.channels >= 3 in
    for p = 0 to n - 1 do
      let base = p * r.channels in
      let s c =
        to8
          (if r.depth = 8 then Bytes.get_uint8 r.samples (base + c)
           else Bytes.get_uint16_be r.samples (2 * (base + c)))
      in
      if color then (
        Bytes.set_uint8 out (3 * p) (s 0);
        Bytes.set_uint8 out ((3 * p) + 1) (s 1);
        Bytes.set_uint8 out ((3 * p) + 2) (s 2))
      else
        let g = s 0 in
        Bytes.set_uint8 out (3 * p) g;
        Bytes.set_uint8 out ((3 * p) + 1) g;
        Bytes.set_uint8 out ((3 * p) + 2) g
    done;
    out
