(* From /proc/self/limits ("Max address space  1536000000  1536000000  bytes"): the Unix
   library has no getrlimit. *)
let limit () =
  match In_channel.with_open_text "/proc/self/limits" In_channel.input_all with
  | exception Sys_error _ -> None
  | text ->
      List.find_map
        (fun line ->
          if String.starts_with ~prefix:"Max address space" line then
            match List.filter (( <> ) "") (String.split_on_char ' ' line) with
            | _ :: _ :: _ :: soft :: _ -> int_of_string_opt soft
            | _ -> None
          else None)
        (String.split_on_char '\n' text)
