let frames_of_string s =
  let bad () = Error (Printf.sprintf "--frames expects A..B or K (got %S)" s) in
  match String.index_opt s '.' with
  | None -> (
      match int_of_string_opt s with Some k when k >= 0 -> Ok (k, k) | _ -> bad ())
  | Some i -> (
      if i + 1 >= String.length s || s.[i + 1] <> '.' then bad ()
      else
        let a = String.sub s 0 i and b = String.sub s (i + 2) (String.length s - i - 2) in
        match (int_of_string_opt a, int_of_string_opt b) with
        | Some a, Some b when a >= 0 && b >= a -> Ok (a, b)
        | _ -> bad ())

type shard = Shard of int * int | Slurm

let shard_of_string s =
  if s = "slurm" then Ok Slurm
  else
    match String.split_on_char '/' s with
    | [ k; n ] -> (
        match (int_of_string_opt k, int_of_string_opt n) with
        | Some k, Some n when n >= 1 && k >= 0 && k < n -> Ok (Shard (k, n))
        | Some _, Some n when n >= 1 ->
            Error (Printf.sprintf "--shard %s: K must be between 0 and %d" s (n - 1))
        | _ ->
            Error (Printf.sprintf "--shard expects K/N (0 <= K < N) or slurm (got %S)" s))
    | _ -> Error (Printf.sprintf "--shard expects K/N (0 <= K < N) or slurm (got %S)" s)

(* A Slurm job array: task IDs MIN, MIN + STEP, … COUNT of them (sbatch --array=0-15). *)
let slurm_shard getenv =
  let var name = getenv name in
  let int name =
    match var name with
    | None -> None
    | Some v -> (
        match int_of_string_opt (String.trim v) with
        | Some n -> Some n
        | None -> Job_error.user "--shard slurm: %s=%S is not a number" name v)
  in
  match (int "SLURM_ARRAY_TASK_ID", int "SLURM_ARRAY_TASK_COUNT") with
  | None, _ | _, None ->
      Job_error.user
        "--shard slurm: SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT are not set; run \
         it as a task of a Slurm job array (sbatch --array=0-15), or give --shard K/N"
  | Some id, Some count ->
      let min = Option.value (int "SLURM_ARRAY_TASK_MIN") ~default:0 in
      let step = Option.value (int "SLURM_ARRAY_TASK_STEP") ~default:1 in
      if
        count < 1 || step < 1 || id < min
        || (id - min) mod step <> 0
        || (id - min) / step >= count
      then
        Job_error.user
          "--shard slurm: task %d is not one of the %d tasks from %d in steps of %d" id
          count min step;
      ((id - min) / step, count)

let resolve_shard ~getenv = function
  | Shard (k, n) -> (k, n)
  | Slurm -> slurm_shard getenv

let shard_frames ~first ~last shard =
  List.filter
    (fun k -> match shard with None -> true | Some (i, n) -> (k - first) mod n = i)
    (List.init (max 0 (last - first + 1)) (fun i -> first + i))
