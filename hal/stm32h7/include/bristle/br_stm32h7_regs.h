/* SPDX-License-Identifier: Apache-2.0 */
/* Minimal register definitions for the STM32H743's own peripherals the
 * bristle port uses, written from the reference manual (RM0433) register
 * maps: RCC, PWR, SYSCFG, FLASH, and the base addresses. The blocks every
 * STM32 port shares (TIMx up to BDTR, GPIO, IWDG, SysTick) are in
 * hal/stm32 (bristle/br_stm32_regs.h).
 *
 * Each block is a struct of volatile 32-bit registers so that the port can be
 * pointed either at the real peripheral address or, in host tests, at a plain
 * struct in RAM (a fake register block). Offsets are checked at compile time
 * in br_stm32h7.c. */
#ifndef BR_STM32H7_REGS_H
#define BR_STM32H7_REGS_H

#include <stdint.h>

#include "bristle/br_stm32_regs.h"

/* ---- Base addresses (RM0433 memory map; ARMv7-M for SysTick) ------------ */
#define BR_STM32H7_TIM2_BASE     0x40000000u  /* D2 APB1, 32-bit GP timer */
#define BR_STM32H7_TIM1_BASE     0x40010000u  /* D2 APB2, advanced timer */
#define BR_STM32H7_GPIOA_BASE    0x58020000u  /* D3 AHB4 */
#define BR_STM32H7_GPIOB_BASE    0x58020400u
#define BR_STM32H7_RCC_BASE      0x58024400u  /* D3 AHB4 */
#define BR_STM32H7_SYSTICK_BASE  BR_STM32_SYSTICK_BASE  /* Cortex-M7 system timer */
#define BR_STM32H7_PWR_BASE      0x58024800u  /* D3 AHB4 */
#define BR_STM32H7_SYSCFG_BASE   0x58000400u  /* D3 APB4 */
#define BR_STM32H7_IWDG1_BASE    0x58004800u  /* D3 APB4, independent watchdog 1 */
#define BR_STM32H7_FLASH_BASE    0x52002000u  /* D1 AHB3, flash interface registers */
#define BR_STM32H7_GPIOD_BASE    0x58020C00u  /* D3 AHB4 */
#define BR_STM32H7_USART3_BASE   0x40004800u  /* D2 APB1 */
#define BR_STM32H7_DMA1_BASE     0x40020000u  /* D2 AHB1 */
#define BR_STM32H7_DMAMUX1_BASE  0x40020800u  /* D2 AHB1: request routing of DMA1 and DMA2 */

/* ---- RCC (clock control, the kernel-clock configuration and the enables) - */
typedef struct {
    volatile uint32_t CR;        /* 0x000 clock control: HSION, PLLxON, ...RDY */
    volatile uint32_t HSICFGR;   /* 0x004 */
    volatile uint32_t CRRCR;     /* 0x008 */
    volatile uint32_t CSICFGR;   /* 0x00C */
    volatile uint32_t CFGR;      /* 0x010 SW (system clock switch), SWS, TIMPRE */
    volatile uint32_t RESERVED1; /* 0x014 */
    volatile uint32_t D1CFGR;    /* 0x018 D1CPRE, HPRE, D1PPRE */
    volatile uint32_t D2CFGR;    /* 0x01C D2PPRE1, D2PPRE2 */
    volatile uint32_t D3CFGR;    /* 0x020 D3PPRE */
    volatile uint32_t RESERVED2; /* 0x024 */
    volatile uint32_t PLLCKSELR; /* 0x028 PLLSRC, DIVM1..3 */
    volatile uint32_t PLLCFGR;   /* 0x02C PLLxRGE, PLLxVCOSEL, DIVxyEN */
    volatile uint32_t PLL1DIVR;  /* 0x030 DIVN1, DIVP1, DIVQ1, DIVR1 */
    volatile uint32_t PLL1FRACR; /* 0x034 */
    volatile uint32_t RESERVED3[38]; /* 0x038..0x0CC */
    volatile uint32_t RSR;       /* 0x0D0 reset status: the reset's cause flags, RMVF clears them */
    volatile uint32_t AHB3ENR;  /* 0x0D4 */
    volatile uint32_t AHB1ENR;  /* 0x0D8 DMA1EN, DMA2EN */
    volatile uint32_t AHB2ENR;  /* 0x0DC */
    volatile uint32_t AHB4ENR;  /* 0x0E0 GPIOx, ... */
    volatile uint32_t APB3ENR;  /* 0x0E4 */
    volatile uint32_t APB1LENR; /* 0x0E8 TIM2..TIM7, TIM12..14, ... */
    volatile uint32_t APB1HENR; /* 0x0EC */
    volatile uint32_t APB2ENR;  /* 0x0F0 TIM1, TIM8, ... */
    volatile uint32_t APB4ENR;  /* 0x0F4 */
} br_stm32h7_rcc_t;

#define BR_RCC_AHB4ENR_GPIOAEN  (1u << 0)
#define BR_RCC_AHB4ENR_GPIOBEN  (1u << 1)
#define BR_RCC_APB1LENR_TIM2EN  (1u << 0)
#define BR_RCC_AHB4ENR_GPIODEN  (1u << 3)
#define BR_RCC_AHB1ENR_DMA1EN   (1u << 0)
#define BR_RCC_APB1LENR_USART3EN (1u << 18)
#define BR_RCC_APB2ENR_TIM1EN   (1u << 0)
#define BR_RCC_APB4ENR_SYSCFGEN (1u << 1)
/* RSR */
#define BR_RCC_RSR_RMVF         (1u << 16)
#define BR_RCC_RSR_IWDG1RSTF    (1u << 26)
/* CR */
#define BR_RCC_CR_HSION         (1u << 0)
#define BR_RCC_CR_HSIRDY        (1u << 2)
#define BR_RCC_CR_PLL1ON        (1u << 24)
#define BR_RCC_CR_PLL1RDY       (1u << 25)
/* CFGR: SW[2:0], SWS[5:3]; 011 = PLL1 (pll1_p_ck) */
#define BR_RCC_CFGR_SW_Msk      (7u << 0)
#define BR_RCC_CFGR_SWS_Msk     (7u << 3)
#define BR_RCC_CFGR_SW_PLL1     (3u << 0)
#define BR_RCC_CFGR_SWS_PLL1    (3u << 3)
#define BR_RCC_CFGR_TIMPRE      (1u << 15)
/* D1CFGR: HPRE[3:0], D1PPRE[6:4], D1CPRE[11:8] */
#define BR_RCC_D1CFGR_HPRE_DIV2   (8u << 0)  /* 1000: rcc_hclk = sys_d1cpre_ck / 2 */
#define BR_RCC_D1CFGR_D1PPRE_DIV2 (4u << 4)  /* 100: APB3 = hclk / 2 */
#define BR_RCC_D1CFGR_D1CPRE_DIV1 (0u << 8)  /* 0xxx: sys_d1cpre_ck = sys_ck */
#define BR_RCC_D1CFGR_Msk         0x0F7Fu
/* D2CFGR: D2PPRE1[6:4] (APB1), D2PPRE2[10:8] (APB2) */
#define BR_RCC_D2CFGR_D2PPRE1_DIV2 (4u << 4)
#define BR_RCC_D2CFGR_D2PPRE2_DIV2 (4u << 8)
#define BR_RCC_D2CFGR_Msk          0x0770u
/* D3CFGR: D3PPRE[6:4] (APB4) */
#define BR_RCC_D3CFGR_D3PPRE_DIV2  (4u << 4)
#define BR_RCC_D3CFGR_Msk          0x0070u
/* PLLCKSELR: PLLSRC[1:0] (00 HSI), DIVM1[9:4] */
#define BR_RCC_PLLCKSELR_PLLSRC_Msk  (3u << 0)
#define BR_RCC_PLLCKSELR_DIVM1_Pos   4u
#define BR_RCC_PLLCKSELR_DIVM1_Msk   (0x3Fu << 4)
/* PLLCFGR: PLL1FRACEN[0], PLL1VCOSEL[1], PLL1RGE[3:2], DIVP1EN[16], DIVQ1EN[17], DIVR1EN[18] */
#define BR_RCC_PLLCFGR_PLL1_Msk      0xFu
#define BR_RCC_PLLCFGR_PLL1RGE_8_16  (3u << 2) /* 11: ref1_ck in 8..16 MHz */
#define BR_RCC_PLLCFGR_DIVP1EN       (1u << 16)
#define BR_RCC_PLLCFGR_DIVQ1EN       (1u << 17)
#define BR_RCC_PLLCFGR_DIVR1EN       (1u << 18)
/* PLL1DIVR: DIVN1[8:0] = N - 1, DIVP1[15:9] = P - 1, DIVQ1[22:16], DIVR1[30:24] */
#define BR_RCC_PLL1DIVR_DIVN1_Pos    0u
#define BR_RCC_PLL1DIVR_DIVP1_Pos    9u
#define BR_RCC_PLL1DIVR_DIVQ1_Pos    16u
#define BR_RCC_PLL1DIVR_DIVR1_Pos    24u

/* ---- PWR (supply and voltage scaling) ------------------------------------ */
typedef struct {
    volatile uint32_t CR1;       /* 0x00 */
    volatile uint32_t CSR1;      /* 0x04 ACTVOSRDY */
    volatile uint32_t CR2;       /* 0x08 */
    volatile uint32_t CR3;       /* 0x0C supply configuration: BYPASS, LDOEN, SCUEN */
    volatile uint32_t CPUCR;     /* 0x10 */
    volatile uint32_t RESERVED0; /* 0x14 */
    volatile uint32_t D3CR;      /* 0x18 VOS[15:14], VOSRDY */
} br_stm32h7_pwr_t;

#define BR_PWR_CSR1_ACTVOSRDY (1u << 13)
#define BR_PWR_CR3_BYPASS     (1u << 0)
#define BR_PWR_CR3_LDOEN      (1u << 1)
#define BR_PWR_CR3_SCUEN      (1u << 2)
#define BR_PWR_D3CR_VOSRDY    (1u << 13)
#define BR_PWR_D3CR_VOS_Msk   (3u << 14)
#define BR_PWR_D3CR_VOS_SCALE1 (3u << 14) /* 11: VOS1 (with SYSCFG ODEN: VOS0) */

/* ---- SYSCFG (only PWRCR: the overdrive that makes VOS1 into VOS0) --------- */
typedef struct {
    volatile uint32_t RESERVED0[11]; /* 0x00..0x28 */
    volatile uint32_t PWRCR;         /* 0x2C ODEN */
} br_stm32h7_syscfg_t;

#define BR_SYSCFG_PWRCR_ODEN (1u << 0)

/* ---- FLASH (only ACR: latency and programming delay) ------------------- */
typedef struct {
    volatile uint32_t ACR; /* 0x000 LATENCY[3:0], WRHIGHFREQ[5:4] */
} br_stm32h7_flash_t;

#define BR_FLASH_ACR_LATENCY_Msk   0xFu
#define BR_FLASH_ACR_WRHIGHFREQ_Pos 4u
#define BR_FLASH_ACR_WRHIGHFREQ_Msk (3u << 4)

/* ---- DMA1 / DMA2 (RM0433 "DMA registers") and DMAMUX1 ------------------ */
/* One stream: the four registers every STM32 port's DMA shares
 * (br_stm32_dma_ch_t: SxCR, SxNDTR, SxPAR, SxM0AR), then M1AR and FCR. */
typedef struct {
    br_stm32_dma_ch_t ch;   /* 0x10 + 0x18 x: SxCR, SxNDTR, SxPAR, SxM0AR */
    volatile uint32_t M1AR; /* 0x20 + 0x18 x */
    volatile uint32_t FCR;  /* 0x24 + 0x18 x: FIFO control; 0 = direct mode */
} br_stm32h7_dma_stream_t;

typedef struct {
    volatile uint32_t LISR;  /* 0x00 streams 0..3's flags */
    volatile uint32_t HISR;  /* 0x04 streams 4..7's */
    volatile uint32_t LIFCR; /* 0x08 their clear bits, streams 0..3 */
    volatile uint32_t HIFCR; /* 0x0C streams 4..7 */
    br_stm32h7_dma_stream_t S[8];
} br_stm32h7_dma_t;

/* SxCR */
#define BR_H7_DMA_SxCR_DIR_P2M   (0u << 6)
#define BR_H7_DMA_SxCR_DIR_M2P   (1u << 6)
#define BR_H7_DMA_SxCR_CIRC      (1u << 8)
#define BR_H7_DMA_SxCR_MINC      (1u << 10) /* PSIZE, MSIZE 00: bytes */
/* LIFCR / HIFCR: a stream's six clear bits (CFEIF, CDMEIF, CTEIF, CHTIF,
 * CTCIF at 0, 2..5 of its field) at 0, 6, 16, 22 for streams 0..3 (4..7) */
#define BR_H7_DMA_IFCR_STREAM    0x3Du
#define BR_H7_DMA_STREAMS        8u

/* DMAMUX1: channel x routes a request to DMA1 stream x (x = 0..7) and DMA2
 * stream x - 8 (8..15); DMAREQ_ID in bits 7:0 of CxCR. */
typedef struct {
    volatile uint32_t CCR[16]; /* 0x00 + 4 x */
} br_stm32h7_dmamux_t;

#define BR_H7_DMAMUX_REQ_MAX     0xFFu
/* RM0433 table "DMAMUX1: assignment of multiplexer inputs to resources" */
#define BR_H7_DMAREQ_USART3_RX   45u
#define BR_H7_DMAREQ_USART3_TX   46u

#endif
