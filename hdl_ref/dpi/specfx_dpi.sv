// specfx_dpi: the golden model of specfx_top through DPI-C, for SystemVerilog testbenches.
//
// The functions are the `specfx_dpi_*` entry points of specfx's C library (capi/,
// libspecfx_c.a or libspecfx_c.so; their C declarations are in capi/include/specfx.h). Link the
// static library into a Verilator build (pass libspecfx_c.a on the command line with
// -LDFLAGS "-lstdc++ -lpthread -ldl"), or load the shared one with -sv_lib. Two-state types
// only; no context functions. Every function that can fail returns 0 on success and -1 on
// failure, with the reason in specfx_dpi_last_error(); a handle is null on failure. A failed
// call writes none of its outputs, and a failed specfx_dpi_machine_cycle takes no clock edge
// (the cycle model is exactly as before it).
// tb_specfx_dpi.sv is a constrained-random testbench with a scoreboard built on them.
`timescale 1ns / 1ps
package specfx_dpi;
    // The model a specfx --config argument names: a built-in name (baseline), a TOML file, or
    // a vector directory written by `specfx vectors`.
    import "DPI-C" function chandle specfx_dpi_open(input string cfg);
    import "DPI-C" function void specfx_dpi_free(input chandle model);
    // The message of this thread's last failure.
    import "DPI-C" function string specfx_dpi_last_error();
    // The exponents of the configuration: how many, and the i-th (ascending); -1 on failure.
    import "DPI-C" function int specfx_dpi_n_count(input chandle model);
    import "DPI-C" function int specfx_dpi_n_at(input chandle model, input int i);
    // The input format's smallest and largest raw codes and the code of 1.0.
    import "DPI-C" function int specfx_dpi_input_codes(input chandle model, output longint min,
                                                       output longint max, output longint one);
    // One per-n constant as specfx_top's port takes it: which = 0 slope, 1 offset,
    // 2 threshold, 3 coef, 4 depth (j(n), in_depth).
    import "DPI-C" function int specfx_dpi_constant(input chandle model, input int n,
                                                    input int which, output longint value);
    // The first code of n the cutoff does not force to zero (a boundary worth aiming at).
    import "DPI-C" function int specfx_dpi_first_live(input chandle model, input int n,
                                                      output longint code);
    // The directed cases specfx vectors always writes (corners, codes with a non-zero output,
    // inputs on and next to every stage's rounding boundary), interleaved: how many, the i-th.
    import "DPI-C" function int specfx_dpi_directed_count(input chandle model);
    import "DPI-C" function int specfx_dpi_directed_at(input chandle model, input int i,
                                                       output int n, output longint c);
    // The output code of input code c and exponent n.
    import "DPI-C" function int specfx_dpi_eval(input chandle model, input longint c,
                                                input int n, output longint out);
    // One stage's value and overflow event (0 none, 1 wrapped, 2 saturated, 3 zeroed); stages
    // are numbered d, t, b, sq1.., coef, out from 0.
    import "DPI-C" function int specfx_dpi_probe(input chandle model, input longint c,
                                                 input int n, input int stage,
                                                 output longint value, output int ev);
    // The cycle model of ARCH (0 pipelined, 1 folded), empty as after reset, and one clock
    // cycle of it: given this cycle's in_valid (with c, n) and out_ready, what specfx_top's
    // ports must show during the cycle (out_tag: the 0-based number of the input the output
    // belongs to); then the clock edge.
    import "DPI-C" function chandle specfx_dpi_machine_new(input chandle model, input int arch);
    import "DPI-C" function void specfx_dpi_machine_free(input chandle machine);
    import "DPI-C" function int specfx_dpi_machine_cycle(
        input chandle machine, input int in_valid, input longint c, input int n,
        input int out_ready, output int in_ready, output int out_valid, output longint out_data,
        output longint out_tag);
endpackage
