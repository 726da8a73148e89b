(** Decimal numerals to the doubles nearest them, exactly as [float_of_string] gives them,
    without its cost for the numerals that generated scenes are full of (17 significant
    digits, as exporters write a double): the decimal's digits scaled by a power of ten
    known to 128 bits, or exact double arithmetic for small ones; [float_of_string] where
    that cannot decide. *)

val read : string -> int -> int -> float
(** [read text s e]: the numeral in bytes \[s, e) of [text] (digits, perhaps a point and
    more, perhaps an exponent: the lexer's numbers). *)

type cursor = { mutable at : int }

val scan : string -> int -> cursor -> float
(** [scan text s c]: the numeral that starts at [text.[s]] (a digit, or a point before
    one), as long as it goes; [c.at] is set to where it ends. *)

val of_parts : int -> int -> float option
(** [of_parts w q]: the double nearest w·10^q ([0 <= w < 2^63]), or [None] where the fast
    ways cannot tell. *)
