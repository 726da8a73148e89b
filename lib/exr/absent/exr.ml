let reason =
  "this lancer was built without OpenEXR (the statically linked build); write a .hdr or \
   .pfm image, or use a lancer built with libopenexr"

let available = Error reason
let encode ?record:_ ~width:_ ~height:_ ~half:_ ~rgb:_ ~alpha:_ () = Error reason
