// specfx_extend: widens a raw code to OUT_W bits, sign-extending it when IN_S is 1 and
// zero-extending it otherwise, so that the wider code stands for the same value.
// OUT_W must be at least IN_W. (A helper of the stage modules; no Rust counterpart: in
// src/fixed the raws live in i64/i128.)
`timescale 1ns / 1ps
`default_nettype none

module specfx_extend #(
    parameter integer IN_W  = 1,  // width of x
    parameter integer IN_S  = 0,  // 1: x is two's complement
    parameter integer OUT_W = 1   // width of y, >= IN_W
) (
    input  wire [IN_W-1:0]  x,
    output wire [OUT_W-1:0] y
);
    generate
        if (OUT_W > IN_W) begin : g_widen
            wire fill = (IN_S != 0) ? x[IN_W-1] : 1'b0;
            assign y = {{(OUT_W - IN_W){fill}}, x};
        end else begin : g_same
            assign y = x;
        end
    endgenerate
endmodule

`default_nettype wire
