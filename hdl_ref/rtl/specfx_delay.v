// specfx_delay: a delay line of LAT registers of W bits sharing one enable: when `en` is high
// at a rising edge, every register takes the value of the one before it (the first takes d);
// when it is low, nothing moves. LAT = 0 is a plain wire. RESET = 1 clears every register on
// the synchronous, active-high `rst` (used for valid bits); RESET = 0 ignores `rst`.
// The stage modules are combinational; each is followed by one of these, as the Rust cycle
// model (src/cycle/) places `lat` registers after each operation (docs/cycle.md).
`timescale 1ns / 1ps
`default_nettype none

module specfx_delay #(
    parameter integer W     = 1,
    parameter integer LAT   = 1,
    parameter integer RESET = 0
) (
    input  wire         clk,
    input  wire         rst,
    input  wire         en,
    input  wire [W-1:0] d,
    output wire [W-1:0] q
);
    generate
        if (LAT == 0) begin : g_wire
            assign q = d;
            wire _unused_ok = &{1'b0, clk, rst, en};
        end else begin : g_regs
            // taps[s] is the input of register s; taps[LAT] is the output.
            wire [(LAT+1)*W-1:0] taps;
            assign taps[W-1:0] = d;
            genvar s;
            for (s = 0; s < LAT; s = s + 1) begin : g_stage
                reg [W-1:0] r;
                always @(posedge clk) begin
                    if (RESET != 0 && rst) r <= {W{1'b0}};
                    else if (en) r <= taps[s*W +: W];
                end
                assign taps[(s+1)*W +: W] = r;
            end
            assign q = taps[LAT*W +: W];
        end
    endgenerate
endmodule

`default_nettype wire
